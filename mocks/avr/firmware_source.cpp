#include "mocks/avr/firmware_source.hpp"

#include <stdexcept>

namespace hil::mocks::avr {

std::filesystem::path pins_file_for(const FirmwareSource& source) {
  if (!source.pins.empty()) return source.pins;
  if (source.sketch.empty()) return {};
  const auto beside = source.sketch.parent_path() / "pins.yaml";
  std::error_code ec;
  return std::filesystem::is_regular_file(beside, ec) ? beside : std::filesystem::path{};
}

AvrConfig resolve_firmware(const FirmwareSource& source) {
  if (source.sketch.empty() == source.elf.empty())
    throw std::invalid_argument("give the firmware as a sketch (.ino) or as an ELF image, not " +
                                std::string(source.sketch.empty() ? "neither" : "both"));
  AvrConfig config;
  if (!source.sketch.empty()) {
    SketchBuildOptions options;
    options.cache_dir = source.cache_dir;
    config.elf = build_sketch(source.sketch, options).elf;
  } else {
    config.elf = source.elf;
  }
  if (source.startup_delay) config.startup_delay = *source.startup_delay;
  const auto pins = pins_file_for(source);
  if (!pins.empty()) config.pins = load_pin_map(pins);
  return config.checked();
}

}  // namespace hil::mocks::avr
