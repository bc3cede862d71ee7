// hil firmware build as a sketch's author runs it: a sketch built into an
// ELF and then found in the cache, -q for scripts, a compile error on the
// sketch's own line, a missing toolchain, and the command lines it refuses.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "tests/apps/hil_cli_support.hpp"
#include "tests/harness/scratch_dir.hpp"

namespace hil::test {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// One cache for the whole program: each sketch avr-gcc compiles takes a
/// second or two.
class HilFirmware : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = std::make_unique<ScratchDir>("hil-firmware-cli");
    write(blink(),
          "// Blink, calling a function defined below it.\n"
          "void setup() { pinMode(13, OUTPUT); }\n"
          "void loop() { toggle(13); delay(250); }\n"
          "void toggle(int pin) { digitalWrite(pin, !digitalRead(pin)); }\n");
  }
  static void TearDownTestSuite() { scratch_.reset(); }
  static fs::path dir() { return scratch_->path(); }
  static fs::path blink() { return dir() / "blink" / "blink.ino"; }
  static std::string cache_args() { return " --cache-dir '" + (dir() / "cache").string() + "'"; }

  static inline std::unique_ptr<ScratchDir> scratch_;
};

TEST_F(HilFirmware, BuildsASketchThenFindsItInTheCache) {
  const fs::path elf = dir() / "out" / "blink.elf";
  fs::create_directories(elf.parent_path());
  const std::string args =
      "firmware build '" + blink().string() + "' -o '" + elf.string() + "'" + cache_args();
  const auto cold = run_hil(args);
  EXPECT_EQ(cold.exit_code, 0) << cold.output;
  EXPECT_THAT(cold.output, ::testing::HasSubstr("elf: " + elf.string() + "\n"));
  EXPECT_THAT(cold.output, ::testing::HasSubstr("cached: no ("));
  EXPECT_THAT(cold.output, ::testing::ContainsRegex("flash: [0-9]+ bytes of 32256 \\("));
  EXPECT_THAT(cold.output, ::testing::ContainsRegex("ram: [0-9]+ bytes of 2048 \\("));
  const std::string bytes = read(elf);
  ASSERT_GE(bytes.size(), 20U);
  EXPECT_EQ(bytes.substr(0, 4), "\177ELF");
  EXPECT_EQ(static_cast<unsigned char>(bytes[18]), 83) << "not an AVR ELF (EM_AVR)";

  fs::remove(elf);
  const auto warm = run_hil(args);
  EXPECT_EQ(warm.exit_code, 0) << warm.output;
  EXPECT_THAT(warm.output, ::testing::HasSubstr("cached: yes ("));
  EXPECT_EQ(read(elf), bytes);

  // -q: the path alone, for scripts; without -o, the ELF in the cache.
  const auto quiet = run_hil("firmware build -q '" + blink().string() + "'" + cache_args());
  EXPECT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_THAT(quiet.output, ::testing::MatchesRegex(".*/cache/[0-9a-f]{64}/sketch\\.elf\n"));
  EXPECT_EQ(read(quiet.output.substr(0, quiet.output.size() - 1)), bytes);
}

TEST_F(HilFirmware, ShowsTheCompilerErrorOnTheSketchLine) {
  const fs::path ino = dir() / "typo" / "typo.ino";
  write(ino,
        "void setup() {}\n"
        "void loop() {\n"
        "  int speed = 1;\n"
        "  analogWrite(5, sped);\n"
        "}\n");
  const auto r = run_hil("firmware build '" + ino.string() + "'" + cache_args());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr(
                            ino.string() + ":4:18: error: 'sped' was not declared in this scope"));
  EXPECT_THAT(r.output, ::testing::HasSubstr("  analogWrite(5, sped);\n"));
  EXPECT_THAT(r.output,
              ::testing::EndsWith("hil firmware build: " + ino.string() + ": does not compile\n"));
  EXPECT_THAT(r.output, ::testing::Not(::testing::HasSubstr("make:")));
}

TEST_F(HilFirmware, SaysWhatIsMissing) {
  const fs::path empty = dir() / "empty";
  fs::create_directories(empty);
  expect_run(says(
      "firmware build '" + blink().string() + "' --toolchain-dir '" + empty.string() + "'" +
          cache_args(),
      1,
      {"hil firmware build: avr-gcc not found (looked for " + (empty / "avr-gcc").string() + ")",
       "install gcc-avr avr-libc arduino-core-avr arduino-mk (ci/install-deps.sh "
       "does)"}));
}

TEST_F(HilFirmware, RefusesWhatIsNotASketch) {
  write(dir() / "notes.txt", "void setup() {}\n");
  for (const auto& run : {
           says("firmware build", 2, {"sketch is required"}),
           says("firmware", 2, {"subcommand"}),
           says("firmware build '" + (dir() / "gone" / "gone.ino").string() + "'", 2,
                {(dir() / "gone" / "gone.ino").string() + ": no such sketch file"}),
           says("firmware build '" + (dir() / "notes.txt").string() + "'", 2,
                {"notes.txt: not a sketch (an Arduino sketch is a .ino file)"}),
           says("firmware build --help", 0,
                {"ATmega328P", "-o,--output", "--cache-dir", "-q,--quiet"}),
       }) {
    expect_run(run);
  }
}

}  // namespace
}  // namespace hil::test
