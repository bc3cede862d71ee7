#pragma once
// Turns an Arduino sketch (a .ino file and the sources beside it) into the
// ELF file an Uno-class board runs (ATmega328P at 16 MHz), with Debian's
// gcc-avr, avr-libc, arduino-core-avr and arduino-mk, the way the Arduino
// IDE would: the .ino gets `#include <Arduino.h>` and a prototype for every
// function it defines, and every diagnostic still names the sketch's own
// file and line. Builds are cached by content (docs/firmware.md, "Building
// a sketch").

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hil::mocks::avr {

struct SketchBuildOptions {
  /// Empty: $XDG_CACHE_HOME/hil/firmware, or ~/.cache/hil/firmware.
  std::filesystem::path cache_dir;
  /// Empty: the ELF stays in the cache only. Otherwise it is copied here
  /// (atomically: a reader sees the old file or the whole new one).
  std::filesystem::path output;
  /// Where avr-gcc, avr-g++, avr-gcc-ar and avr-objcopy are (empty: /usr/bin).
  std::filesystem::path toolchain_dir;
  /// Where Arduino.mk and hardware/arduino/avr are (empty: /usr/share/arduino).
  std::filesystem::path arduino_dir;
  /// Compilers run at once (make -j); 0: one per CPU.
  int jobs = 0;
};

struct SketchBuild {
  std::filesystem::path elf;  ///< `output` when given, else the ELF in the cache
  bool cached = false;        ///< true: the cache held it and nothing was compiled
  std::string key;            ///< the cache key: SHA-256 of every input, in hex
  std::string warnings;       ///< what the compiler printed about the sketch (a fresh build)
};

/// What an Arduino Uno holds (arduino-core-avr's boards.txt: uno.upload.
/// maximum_size, the flash less the 512-byte bootloader, and
/// maximum_data_size, the ATmega328P's static RAM).
inline constexpr std::uint32_t kUnoFlashBytes = 32256;
inline constexpr std::uint32_t kUnoRamBytes = 2048;

/// A sketch that cannot be built: what() says what was wrong and where; for
/// a sketch that does not compile it holds the compiler's error lines, and
/// diagnostics() everything the compiler printed.
class SketchBuildError : public std::runtime_error {
 public:
  enum class Kind {
    kSketch,     ///< the sketch path: missing, not a .ino, a file name make cannot take
    kToolchain,  ///< a compiler, avr-libc, the Arduino core or arduino-mk is missing
    kCompile,    ///< the compiler or linker rejected the sketch
    kIo,         ///< the cache or the output could not be written
  };
  SketchBuildError(Kind kind, const std::string& what, std::string diagnostics = {})
      : std::runtime_error(what), kind_(kind), diagnostics_(std::move(diagnostics)) {}
  Kind kind() const { return kind_; }
  /// Everything the compilers printed (kCompile), else empty.
  const std::string& diagnostics() const { return diagnostics_; }

 private:
  Kind kind_;
  std::string diagnostics_;
};

/// Builds the sketch `ino` (its folder's other .ino files follow it, and the
/// folder's .cpp, .c, .S, .h and .hpp files are compiled too) or finds it in
/// the cache. Throws SketchBuildError.
SketchBuild build_sketch(const std::filesystem::path& ino, const SketchBuildOptions& options = {});

/// One .ino file of a sketch.
struct SketchFile {
  std::filesystem::path path;  ///< as diagnostics should name it
  std::string text;
};

/// The C++ the compiler sees for a sketch's .ino files (the main one first):
/// `#include <Arduino.h>`, the files' text with `#line` directives naming
/// each file's own lines, and, just before the first function definition, a
/// prototype for every top-level function defined without one (not for
/// templates, member functions, or names already declared; default
/// arguments are left to the definition).
std::string generate_sketch_cpp(const std::vector<SketchFile>& files);

/// generate_sketch_cpp for a sketch of one file.
inline std::string insert_prototypes(std::string_view text, const std::filesystem::path& path) {
  return generate_sketch_cpp({SketchFile{path, std::string(text)}});
}

/// SHA-256 of `bytes` as 64 lowercase hex digits (FIPS 180-4).
std::string sha256_hex(std::string_view bytes);

/// What an AVR ELF file says about itself.
struct AvrElfInfo {
  std::uint16_t machine = 0;  ///< e_machine: 83 (EM_AVR) for AVR code
  /// avr-gcc's architecture number, e_flags' low 7 bits: 5 for avr5 (the
  /// ATmega328P), 6 for avr6 (the ATmega2560), ...
  std::uint32_t architecture = 0;
  std::uint32_t flash_bytes = 0;  ///< .text + .data: what the board's flash holds
  std::uint32_t ram_bytes = 0;    ///< .data + .bss + .noinit: static RAM before the stack
};

/// Reads the ELF header and section sizes of `elf` (32-bit little-endian).
/// Throws SketchBuildError naming the file when it is not such an ELF.
AvrElfInfo read_avr_elf(const std::filesystem::path& elf);

}  // namespace hil::mocks::avr
