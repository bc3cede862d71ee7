// hil firmware build: turn an Arduino sketch into the ELF file the emulated
// Uno runs (mocks/avr/sketch_build.hpp, docs/firmware.md).

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "apps/hil/cli_common.hpp"
#include "mocks/avr/sketch_build.hpp"

namespace hil::apps {

namespace {

namespace avr = mocks::avr;

struct FirmwareBuildArgs {
  std::string sketch;
  std::string output;
  std::string cache_dir;
  std::string toolchain_dir;
  std::string arduino_dir;
  bool quiet = false;
};

std::string percent_of(std::uint32_t used, std::uint32_t of) {
  char text[16];
  std::snprintf(text, sizeof text, "%.1f %%", 100.0 * used / of);
  return text;
}

int run_firmware_build(const FirmwareBuildArgs& args) {
  avr::SketchBuildOptions options;
  options.output = args.output;
  options.cache_dir = args.cache_dir;
  options.toolchain_dir = args.toolchain_dir;
  options.arduino_dir = args.arduino_dir;
  const auto start = std::chrono::steady_clock::now();
  avr::SketchBuild build;
  try {
    build = avr::build_sketch(args.sketch, options);
  } catch (const avr::SketchBuildError& e) {
    if (e.kind() == avr::SketchBuildError::Kind::kCompile && !e.diagnostics().empty()) {
      std::cerr << e.diagnostics();
      // The first line of what() ("SKETCH: does not compile:"); the
      // compiler's lines above already say the rest.
      std::string what = e.what();
      what = what.substr(0, what.find('\n'));
      if (what.ends_with(':')) what.pop_back();
      std::cerr << "hil firmware build: " << what << '\n';
    } else {
      std::cerr << "hil firmware build: " << e.what() << '\n';
    }
    return e.kind() == avr::SketchBuildError::Kind::kSketch ? 2 : 1;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!build.warnings.empty()) std::cerr << build.warnings;
  if (args.quiet) {
    std::cout << build.elf.string() << '\n';
    return 0;
  }
  avr::AvrElfInfo info;
  try {
    info = avr::read_avr_elf(build.elf);
  } catch (const avr::SketchBuildError& e) {
    std::cerr << "hil firmware build: " << e.what() << '\n';
    return 1;
  }
  char took[32];
  std::snprintf(took, sizeof took, "%.2f s", seconds);
  std::cout << "elf: " << build.elf.string() << '\n'
            << "cached: " << (build.cached ? "yes" : "no") << " (" << took << ", key "
            << build.key.substr(0, 16) << ")\n"
            << "flash: " << info.flash_bytes << " bytes of " << avr::kUnoFlashBytes << " ("
            << percent_of(info.flash_bytes, avr::kUnoFlashBytes) << ")\n"
            << "ram: " << info.ram_bytes << " bytes of " << avr::kUnoRamBytes << " ("
            << percent_of(info.ram_bytes, avr::kUnoRamBytes) << ", before the stack)\n";
  return 0;
}

}  // namespace

void register_firmware(CLI::App& app, std::function<int()>& run) {
  auto* firmware = app.add_subcommand(
      "firmware", "Build real Arduino sketches for the emulated Uno (docs/firmware.md)");
  firmware->require_subcommand(1);

  auto args = std::make_shared<FirmwareBuildArgs>();
  auto* build = firmware->add_subcommand(
      "build", "Compile a sketch (.ino) for an Arduino Uno (ATmega328P, 16 MHz) into an ELF file");
  build
      ->add_option("sketch", args->sketch,
                   "The sketch's .ino file; its folder's other .ino, .cpp, .c, .S and .h files "
                   "are part of it")
      ->required();
  build->add_option("-o,--output", args->output,
                    "Copy the ELF here (default: it stays in the cache, at the path printed)");
  build->add_option("--cache-dir", args->cache_dir,
                    "The build cache (default: $XDG_CACHE_HOME/hil/firmware or "
                    "~/.cache/hil/firmware)");
  build->add_option("--toolchain-dir", args->toolchain_dir,
                    "Where avr-gcc and its tools are (default: /usr/bin)");
  build->add_option("--arduino-dir", args->arduino_dir,
                    "Where Arduino.mk and hardware/arduino/avr are (default: /usr/share/arduino)");
  build->add_flag("-q,--quiet", args->quiet, "Print only the ELF's path");
  build->footer(
      "Prints the ELF's path, whether it came from the cache, and the flash and RAM it uses.\n"
      "Exit status: 0 built; 1 the sketch does not compile, or the toolchain is missing;\n"
      "2 a malformed command line, or a sketch path that is not a .ino file.\n"
      "Examples:\n"
      "  hil firmware build scenarios/firmware/hil_arduino/hil_arduino.ino\n"
      "  hil firmware build robot/robot.ino -o robot.elf --cache-dir build/firmware-cache -q");
  build->callback([&run, args] { run = [args] { return run_firmware_build(*args); }; });
}

}  // namespace hil::apps
