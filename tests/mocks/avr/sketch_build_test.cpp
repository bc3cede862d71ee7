// Building an Arduino sketch for the emulated Uno: the prototypes the
// builder adds to a .ino (and the #line directives that keep every
// diagnostic on the sketch's own lines), the cache key's hash, and real
// builds with avr-gcc: an AVR ELF, a cache hit, a compile error on the
// right line, a missing toolchain.

#include "mocks/avr/sketch_build.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "tests/harness/scratch_dir.hpp"

namespace hil::mocks::avr {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

// ---------------------------------------------------------------- prototypes

/// One line of generated C++ and where #line says it comes from.
struct MappedLine {
  std::string file;
  int line = 0;
  std::string text;
};

/// Follows the #line directives of `cpp` as the compiler does.
std::vector<MappedLine> map_lines(const std::string& cpp) {
  std::vector<MappedLine> out;
  std::istringstream in(cpp);
  std::string file;
  int line = 0;
  for (std::string text; std::getline(in, text);) {
    if (text.starts_with("#line ")) {
      std::istringstream directive(text.substr(6));
      directive >> line;
      const auto open = text.find('"');
      file = text.substr(open + 1, text.rfind('"') - open - 1);
      continue;
    }
    out.push_back({file, line, text});
    ++line;
  }
  return out;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    out.push_back(line);
  return out;
}

/// Every line of every sketch file is in `cpp` under its own file name and
/// line number (a line the prototypes split keeps its column), and every
/// added line is a prototype that #line puts on its function's first line.
void expect_lines_map_back(const std::vector<SketchFile>& files, const std::string& cpp) {
  std::map<std::string, std::vector<std::string>> originals;
  for (const auto& f : files)
    originals[f.path.string()] = lines_of(f.text);
  std::map<std::string, std::vector<bool>> seen;
  for (const auto& [name, lines] : originals)
    seen[name].assign(lines.size(), false);
  const auto mapped = map_lines(cpp);
  ASSERT_FALSE(mapped.empty());
  EXPECT_EQ(mapped.front().text, "#include <Arduino.h>");
  for (std::size_t i = 1; i < mapped.size(); ++i) {
    const auto& m = mapped[i];
    SCOPED_TRACE(m.file + ":" + std::to_string(m.line) + ": " + m.text);
    ASSERT_TRUE(originals.contains(m.file));
    const auto& lines = originals[m.file];
    ASSERT_GE(m.line, 1);
    ASSERT_LE(static_cast<std::size_t>(m.line), lines.size());
    const std::string& original = lines[static_cast<std::size_t>(m.line) - 1];
    const std::size_t indent = m.text.find_first_not_of(' ');
    const bool same =
        m.text == original || (indent != std::string::npos && m.text.size() == original.size() &&
                               original.ends_with(m.text.substr(indent)));
    if (same) {
      seen[m.file][static_cast<std::size_t>(m.line) - 1] = true;
    } else if (!m.text.empty() && original.starts_with(m.text) && i + 1 < mapped.size() &&
               mapped[i + 1].text.ends_with(");")) {
      // The first part of a line split for the prototypes that follow.
    } else {
      // A prototype: "static int f(int a);" for the line "static int f(int a = 2) {".
      ASSERT_TRUE(m.text.ends_with(");")) << "an added line that is not a prototype";
      const std::string first_word = m.text.substr(0, m.text.find_first_of(" ("));
      EXPECT_THAT(original, HasSubstr(first_word));
    }
  }
  for (const auto& [name, flags] : seen) {
    for (std::size_t n = 0; n < flags.size(); ++n)
      EXPECT_TRUE(flags[n]) << name << ":" << n + 1 << " is missing from the generated C++";
  }
}

/// The prototypes the builder added (lines of `cpp` not in `text`).
std::vector<std::string> added_lines(const std::string& text, const std::string& cpp) {
  const auto original = lines_of(text);
  std::vector<std::string> out;
  for (const auto& m : map_lines(cpp)) {
    if (m.file.empty()) continue;
    const bool same = m.line >= 1 && static_cast<std::size_t>(m.line) <= original.size() &&
                      original[static_cast<std::size_t>(m.line) - 1].ends_with(
                          m.text.substr(std::min(m.text.size(), m.text.find_first_not_of(' '))));
    if (!same) out.push_back(m.text);
  }
  return out;
}

std::vector<std::string> prototypes_for(const std::string& text) {
  const std::string cpp = insert_prototypes(text, "/sketches/robot/robot.ino");
  expect_lines_map_back({{"/sketches/robot/robot.ino", text}}, cpp);
  return added_lines(text, cpp);
}

TEST(SketchPrototypes, GoBeforeTheFirstFunctionWithLineDirectives) {
  const std::string sketch =
      "// Blink\n"
      "#include <Servo.h>\n"
      "#define LED 13\n"
      "\n"
      "struct Step { int pin; int ms; };\n"
      "\n"
      "void setup() { pinMode(LED, OUTPUT); }\n"
      "\n"
      "void loop() { blink({LED, 500}); }\n"
      "\n"
      "void blink(Step s) {\n"
      "  digitalWrite(s.pin, HIGH);\n"
      "}\n";
  EXPECT_EQ(insert_prototypes(sketch, "/sketches/blink/blink.ino"),
            "#include <Arduino.h>\n"
            "#line 1 \"/sketches/blink/blink.ino\"\n"
            "// Blink\n"
            "#include <Servo.h>\n"
            "#define LED 13\n"
            "\n"
            "struct Step { int pin; int ms; };\n"
            "\n"
            "#line 7 \"/sketches/blink/blink.ino\"\n"
            "void setup();\n"
            "#line 9 \"/sketches/blink/blink.ino\"\n"
            "void loop();\n"
            "#line 11 \"/sketches/blink/blink.ino\"\n"
            "void blink(Step s);\n"
            "#line 7 \"/sketches/blink/blink.ino\"\n"
            "void setup() { pinMode(LED, OUTPUT); }\n"
            "\n"
            "void loop() { blink({LED, 500}); }\n"
            "\n"
            "void blink(Step s) {\n"
            "  digitalWrite(s.pin, HIGH);\n"
            "}\n");
}

TEST(SketchPrototypes, SeeOnlyTopLevelFunctionsThroughNestedBraces) {
  EXPECT_THAT(
      prototypes_for("int count = 0;\n"
                     "void loop() {\n"
                     "  if (count > 2) {\n"
                     "    for (int i = 0; i < 3; ++i) { step(i); }\n"
                     "  } else { struct Local { int f() { return 1; } } l; count += l.f(); }\n"
                     "}\n"
                     "void step(int i) { while (i--) { delay(1); } }\n"),
      ::testing::ElementsAre("void loop();", "void step(int i);"));
}

TEST(SketchPrototypes, IgnoreBracesInCommentsStringsAndCharacters) {
  EXPECT_THAT(prototypes_for("/* a comment { void fake_a() {\n"
                             "   } still a comment */\n"
                             "// void fake_b() { }\n"
                             "void loop() {\n"
                             "  Serial.println(\"} void fake_c() {\");\n"
                             "  char open = '{';  char quote = '\\'';\n"
                             "  const char* raw = R\"x(} void fake_d() { \")x\";\n"
                             "  long big = 1'000'000;  // } {\n"
                             "}\n"
                             "int after(const char* s = \"{\") { return s[0]; }\n"),
              ::testing::ElementsAre("void loop();", "int after(const char* s);"));
}

TEST(SketchPrototypes, SkipPreprocessorLinesEvenContinuedOnes) {
  EXPECT_THAT(prototypes_for("#define BODY(x) { \\\n"
                             "  x; }\n"
                             "  #if defined(FOO) // {\n"
                             "#endif\n"
                             "void loop() { BODY(delay(1)) }\n"),
              ::testing::ElementsAre("void loop();"));
}

TEST(SketchPrototypes, LeaveFunctionsAlreadyDeclaredAlone) {
  const std::string sketch =
      "int twice(int x);\n"
      "void loop() { Serial.println(twice(3)); }\n"
      "int twice(int x) { return 2 * x; }\n";
  EXPECT_THAT(prototypes_for(sketch), ::testing::ElementsAre("void loop();"));
}

TEST(SketchPrototypes, KeepDefaultArgumentsOnlyWhereTheSketchPutThem) {
  // In the prototype only: the sketch's own declaration stands.
  EXPECT_THAT(prototypes_for("void flash(int times = 3);\n"
                             "void loop() { flash(); }\n"
                             "void flash(int times) { while (times--) delay(100); }\n"),
              ::testing::ElementsAre("void loop();"));
  // In the definition only: the added prototype leaves them out (a default
  // may be given once), so calls after the definition may still omit them.
  EXPECT_THAT(prototypes_for("void pulse(int pin, int ms = 10, char mode = ',') {\n"
                             "  delay(ms);\n"
                             "}\n"),
              ::testing::ElementsAre("void pulse(int pin, int ms, char mode);"));
}

TEST(SketchPrototypes, KeepStaticAndSpecifiersAndJoinSignaturesOnSeveralLines) {
  EXPECT_THAT(prototypes_for("static int clamp(int v,\n"
                             "                 int lo,   // lowest\n"
                             "                 int hi) {\n"
                             "  return v < lo ? lo : v > hi ? hi : v;\n"
                             "}\n"
                             "inline unsigned long\n"
                             "elapsed_ms(unsigned long since) { return millis() - since; }\n"),
              ::testing::ElementsAre("static int clamp(int v, int lo, int hi);",
                                     "inline unsigned long elapsed_ms(unsigned long since);"));
}

TEST(SketchPrototypes, LeaveTemplatesMembersMacrosAndInitialisersAlone) {
  EXPECT_THAT(prototypes_for("template <typename T>\n"
                             "T biggest(T a, T b) { return a > b ? a : b; }\n"
                             "struct Motor { void run(); int speed; };\n"
                             "void Motor::run() { speed = 1; }\n"
                             "ISR(TIMER1_COMPA_vect) { }\n"
                             "int table[] = {1, 2, 3};\n"
                             "auto twice = [](int x) { return 2 * x; };\n"
                             "namespace pins { int left() { return 5; } }\n"
                             "extern \"C\" { void c_side() { } }\n"
                             "void loop() { }\n"),
              ::testing::ElementsAre("void loop();"));
}

TEST(SketchPrototypes, JoinTheFolderInoFilesAfterTheMainOne) {
  const std::vector<SketchFile> files = {
      {"/s/robot/robot.ino", "#include \"motors.h\"\nvoid loop() { drive(1); }\n"},
      {"/s/robot/drive.ino", "// Driving\nvoid drive(int speed) {\n  analogWrite(5, speed);\n}\n"},
  };
  const std::string cpp = generate_sketch_cpp(files);
  expect_lines_map_back(files, cpp);
  EXPECT_EQ(cpp,
            "#include <Arduino.h>\n"
            "#line 1 \"/s/robot/robot.ino\"\n"
            "#include \"motors.h\"\n"
            "#line 2 \"/s/robot/robot.ino\"\n"
            "void loop();\n"
            "#line 2 \"/s/robot/drive.ino\"\n"
            "void drive(int speed);\n"
            "#line 2 \"/s/robot/robot.ino\"\n"
            "void loop() { drive(1); }\n"
            "#line 1 \"/s/robot/drive.ino\"\n"
            "// Driving\n"
            "void drive(int speed) {\n"
            "  analogWrite(5, speed);\n"
            "}\n");
}

TEST(SketchPrototypes, SplitALineInTheMiddleWithoutMovingItsColumns) {
  const std::string sketch = "int x; /* note\n */ void loop() { go(); } void go() { }";
  const std::string cpp = insert_prototypes(sketch, "/s/a/a.ino");
  expect_lines_map_back({{"/s/a/a.ino", sketch}}, cpp);
  EXPECT_THAT(cpp, HasSubstr("#line 2 \"/s/a/a.ino\"\n    void loop() { go(); } void go() { }\n"));
}

TEST(SketchPrototypes, LeaveASketchWithoutFunctionsAsItIs) {
  EXPECT_EQ(insert_prototypes("int x = 1;", "/s/a/a.ino"),
            "#include <Arduino.h>\n#line 1 \"/s/a/a.ino\"\nint x = 1;\n");
}

// ---------------------------------------------------------------- SHA-256

TEST(SketchBuildKey, IsSha256) {
  // FIPS 180-2 appendix B's examples, and the empty message.
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// ---------------------------------------------------------------- builds

void write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// A Blink sketch that calls a function defined below it, and a function
/// of a .cpp beside it.
void write_blink(const fs::path& folder, int on_ms) {
  write(folder / "blink.ino",
        "// Blink through a helper defined further down.\n"
        "#include \"half.h\"\n"
        "#define LED 13\n"
        "\n"
        "void setup() { pinMode(LED, OUTPUT); }\n"
        "\n"
        "void loop() { blink(" +
            std::to_string(on_ms) +
            "); }\n"
            "\n"
            "static void blink(int on_ms) {\n"
            "  digitalWrite(LED, HIGH);\n"
            "  delay(on_ms);\n"
            "  digitalWrite(LED, LOW);\n"
            "  delay(half(on_ms));\n"
            "}\n");
  write(folder / "half.h", "#pragma once\nint half(int x);\n");
  write(folder / "half.cpp", "#include \"half.h\"\nint half(int x) { return x / 2; }\n");
}

/// Each test has a folder of its own and a cache in it. avr-gcc takes a
/// second or so for each sketch it compiles, and CTest runs each test in a
/// process of its own, so the program compiles three sketches in all: the
/// first test's two and the compile error.
class SketchBuildTest : public ::testing::Test {
 protected:
  fs::path dir() const { return scratch_.path(); }
  fs::path cache() const { return dir() / "cache"; }
  SketchBuildOptions options() const {
    SketchBuildOptions o;
    o.cache_dir = cache();
    return o;
  }
  /// The build folders left in the cache (none, once a build is over).
  std::vector<std::string> leftovers() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(cache()))
      if (e.path().filename().string().starts_with(".")) out.push_back(e.path().string());
    return out;
  }
  static double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  hil::test::ScratchDir scratch_{"hil-sketch-build"};
};

TEST_F(SketchBuildTest, BuildsAnAvrElfOnceThenFindsItByContent) {
  write_blink(dir() / "blink", 500);
  auto start = std::chrono::steady_clock::now();
  const SketchBuild first = build_sketch(dir() / "blink" / "blink.ino", options());
  const double cold_s = seconds_since(start);
  EXPECT_FALSE(first.cached);
  EXPECT_EQ(first.elf, cache() / first.key / "sketch.elf");
  EXPECT_THAT(first.key, ::testing::MatchesRegex("[0-9a-f]{64}"));
  EXPECT_TRUE(first.warnings.empty()) << first.warnings;
  const std::string elf = read(first.elf);
  ASSERT_GE(elf.size(), 20U);
  EXPECT_EQ(elf.substr(0, 4), "\177ELF");
  EXPECT_EQ(static_cast<unsigned char>(elf[18]) | (static_cast<unsigned char>(elf[19]) << 8), 83)
      << "e_machine is not EM_AVR";
  const AvrElfInfo info = read_avr_elf(first.elf);
  EXPECT_EQ(info.machine, 83);
  // Blink with the core's timer and pin code: a few hundred bytes at least,
  // and far from the Uno's limits.
  EXPECT_GT(info.flash_bytes, 500U);
  EXPECT_LT(info.flash_bytes, kUnoFlashBytes / 4);
  EXPECT_GT(info.ram_bytes, 0U);
  EXPECT_LT(info.ram_bytes, kUnoRamBytes / 4);

  // Again, into a file of its own: from the cache, at once.
  SketchBuildOptions o = options();
  o.output = dir() / "out" / "blink.elf";
  fs::create_directories(o.output.parent_path());
  start = std::chrono::steady_clock::now();
  const SketchBuild again = build_sketch(dir() / "blink" / "blink.ino", o);
  const double cached_s = seconds_since(start);
  EXPECT_TRUE(again.cached);
  EXPECT_EQ(again.key, first.key);
  EXPECT_EQ(again.elf, o.output);
  EXPECT_LT(cached_s, 1.0);
  EXPECT_EQ(read(o.output), elf);
  std::cout << "cold build: " << cold_s << " s, cached: " << cached_s << " s\n";

  // The same files elsewhere: a cache hit.
  write_blink(dir() / "elsewhere" / "blink", 500);
  const SketchBuild moved = build_sketch(dir() / "elsewhere" / "blink" / "blink.ino", options());
  EXPECT_TRUE(moved.cached);
  EXPECT_EQ(moved.key, first.key);
  // One byte changed in the .cpp beside the sketch: a new key and a build.
  write_blink(dir() / "changed" / "blink", 500);
  write(dir() / "changed" / "blink" / "half.cpp",
        "#include \"half.h\"\nint half(int x) { return x / 3; }\n");
  const SketchBuild changed = build_sketch(dir() / "changed" / "blink" / "blink.ino", options());
  EXPECT_FALSE(changed.cached);
  EXPECT_NE(changed.key, first.key);
  EXPECT_NE(read(changed.elf), elf);
  EXPECT_THAT(leftovers(), ::testing::IsEmpty());
}

TEST_F(SketchBuildTest, NamesTheSketchLineOfACompileError) {
  const fs::path ino = dir() / "broken" / "broken.ino";
  write(ino,
        "// A sketch with a typo on line 7.\n"
        "void setup() {}\n"
        "\n"
        "void loop() {\n"
        "  later();\n"
        "  int speed = 3;\n"
        "  sped = speed + 1;\n"
        "}\n"
        "void later() {}\n");
  try {
    build_sketch(ino, options());
    FAIL() << "a sketch with an undeclared name built";
  } catch (const SketchBuildError& e) {
    EXPECT_EQ(e.kind(), SketchBuildError::Kind::kCompile);
    EXPECT_THAT(e.what(), HasSubstr(ino.string() + ": does not compile"));
    EXPECT_THAT(e.what(), HasSubstr(ino.string() + ":7:3: error: 'sped' was not declared"));
    EXPECT_THAT(e.diagnostics(), HasSubstr("broken.ino:7:3: error:"));
    EXPECT_THAT(e.diagnostics(), HasSubstr("   sped = speed + 1;\n"));
    EXPECT_THAT(e.diagnostics(), Not(HasSubstr(".ino.cpp")));
    EXPECT_THAT(e.diagnostics(), Not(HasSubstr("make:")));
  }
  EXPECT_FALSE(fs::exists(dir() / "broken" / "obj"));
  EXPECT_THAT(leftovers(), ::testing::IsEmpty());
}

TEST_F(SketchBuildTest, SaysWhichToolIsMissingAndHowToInstallIt) {
  write_blink(dir() / "blink", 500);
  const fs::path empty = dir() / "no-tools";
  fs::create_directories(empty);
  SketchBuildOptions o = options();
  o.toolchain_dir = empty;
  try {
    build_sketch(dir() / "blink" / "blink.ino", o);
    FAIL() << "built without a compiler";
  } catch (const SketchBuildError& e) {
    EXPECT_EQ(e.kind(), SketchBuildError::Kind::kToolchain);
    EXPECT_THAT(e.what(),
                HasSubstr("avr-gcc not found (looked for " + (empty / "avr-gcc").string()));
    EXPECT_THAT(e.what(), HasSubstr("install gcc-avr avr-libc arduino-core-avr arduino-mk "
                                    "(ci/install-deps.sh does)"));
  }
  o = options();
  o.arduino_dir = empty;
  try {
    build_sketch(dir() / "blink" / "blink.ino", o);
    FAIL() << "built without the Arduino core";
  } catch (const SketchBuildError& e) {
    EXPECT_EQ(e.kind(), SketchBuildError::Kind::kToolchain);
    EXPECT_THAT(e.what(), HasSubstr("the Arduino AVR core (arduino-core-avr) not found"));
  }
}

TEST_F(SketchBuildTest, RefusesWhatIsNotASketch) {
  auto kind_and_what = [this](const fs::path& path) -> std::pair<int, std::string> {
    try {
      build_sketch(path, options());
    } catch (const SketchBuildError& e) {
      return {static_cast<int>(e.kind()), e.what()};
    }
    return {-1, "built"};
  };
  const int sketch_kind = static_cast<int>(SketchBuildError::Kind::kSketch);
  EXPECT_EQ(
      kind_and_what(dir() / "none" / "none.ino"),
      std::pair(sketch_kind, (dir() / "none" / "none.ino").string() + ": no such sketch file"));
  write(dir() / "text" / "notes.txt", "void setup() {}\n");
  EXPECT_EQ(kind_and_what(dir() / "text" / "notes.txt"),
            std::pair(sketch_kind, (dir() / "text" / "notes.txt").string() +
                                       ": not a sketch (an Arduino sketch is a .ino file)"));
  // A source whose name the shell under make would read as a command.
  write_blink(dir() / "odd", 500);
  write(dir() / "odd" / "a;b.cpp", "int x;\n");
  const auto [kind, what] = kind_and_what(dir() / "odd" / "blink.ino");
  EXPECT_EQ(kind, sketch_kind);
  EXPECT_THAT(what, HasSubstr("a;b.cpp: a sketch's file names may hold only"));
}

TEST(SketchElf, RefusesAFileThatIsNotAnElf) {
  hil::test::ScratchDir dir("hil-sketch-elf");
  write(dir.path() / "x.elf", "not an elf at all, but long enough to have a header. ok");
  EXPECT_THROW(
      {
        try {
          read_avr_elf(dir.path() / "x.elf");
        } catch (const SketchBuildError& e) {
          EXPECT_EQ(std::string(e.what()), (dir.path() / "x.elf").string() + ": not an ELF file");
          throw;
        }
      },
      SketchBuildError);
}

}  // namespace
}  // namespace hil::mocks::avr
