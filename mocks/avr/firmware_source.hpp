#pragma once
// Where an emulated board's firmware comes from: a sketch (built, and
// cached, by avr::build_sketch) or a ready ELF image, and the pin map that
// wires it. What `hil mock arduino --sketch/--elf/--pins`, `hil run
// --sketch/--elf` and a scenario's `car: {firmware: ...}` give.

#include <filesystem>
#include <optional>
#include <string>

#include "mocks/avr/avr_firmware.hpp"
#include "mocks/avr/sketch_build.hpp"

namespace hil::mocks::avr {

struct FirmwareSource {
  std::filesystem::path sketch;  ///< a .ino to build; or
  std::filesystem::path elf;     ///< an image built already
  /// A pin map file; empty: the sketch folder's `pins.yaml` when there is
  /// one, else the default pin map.
  std::filesystem::path pins;
  /// Where built sketches are kept (SketchBuildOptions::cache_dir).
  std::filesystem::path cache_dir;
  /// From the port opening to the first instruction (AvrConfig::
  /// startup_delay); nullopt: the chip's own 66 ms.
  std::optional<Duration> startup_delay;
};

/// The sketch's pin map file by the naming rule above, or empty.
std::filesystem::path pins_file_for(const FirmwareSource& source);

/// The config that runs `source` on the emulated board: the sketch built
/// (or found in the cache), the image checked, the pin map read. Throws
/// SketchBuildError (a sketch that does not build), config::ConfigError (a
/// pin map file), std::invalid_argument (an image for another chip,
/// neither or both of `sketch` and `elf`).
AvrConfig resolve_firmware(const FirmwareSource& source);

}  // namespace hil::mocks::avr
