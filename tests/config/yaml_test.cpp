// The YAML reading kit of every hil loader: errors at the node they are
// about, key checks with a suggestion, and the shared values.
#include "config/yaml.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>

namespace hil::config {
namespace {

using namespace std::chrono_literals;
using testing::HasSubstr;

/// What `fn` throws, as a ConfigError (fails the test when it throws nothing).
ConfigError error_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "no ConfigError";
  return ConfigError("", 0, 0, "");
}

TEST(ConfigError, NamesFileLineAndColumnAndKeepsTheMessageApart) {
  const ConfigError e("lab.yaml", 12, 15, "radius: expected a positive number");
  EXPECT_STREQ(e.what(), "lab.yaml:12:15: radius: expected a positive number");
  EXPECT_EQ(e.file(), "lab.yaml");
  EXPECT_EQ(e.line(), 12);
  EXPECT_EQ(e.column(), 15);
  EXPECT_EQ(e.message(), "radius: expected a positive number");
  EXPECT_STREQ(ConfigError("x.yaml", 0, 0, "cannot read").what(), "x.yaml: cannot read");
}

TEST(YamlReader, ASyntaxErrorIsReportedWhereItIs) {
  const Reader r("t.yaml");
  const auto e = error_of([&] { r.parse("a: 1\nb: [1, 2\n"); });
  EXPECT_EQ(e.line(), 3);
  EXPECT_THAT(e.message(), testing::StartsWith("not valid YAML: "));
  EXPECT_EQ(error_of([&] { r.parse(std::string(20000, '[')); }).message(),
            "not valid YAML: nested too deeply");
}

TEST(YamlReader, UnknownKeysSuggestTheNearestAndDuplicatesAreRefused) {
  const Reader r("t.yaml");
  const Keys allowed = {"name", "steps", "expect"};
  r.check_keys(r.parse("name: a\nsteps: []\n"), allowed, "the scenario");
  const auto typo = error_of([&] { r.check_keys(r.parse("stpes: []\n"), allowed, "the scenario"); });
  EXPECT_STREQ(typo.what(),
               "t.yaml:1:1: the scenario: unknown key 'stpes' (allowed: name, steps, expect); "
               "did you mean 'steps'?");
  const auto far = error_of([&] { r.check_keys(r.parse("zzzzzz: 1\n"), allowed, "", "takes"); });
  EXPECT_EQ(far.message(), "unknown key 'zzzzzz' (takes: name, steps, expect)");
  const auto twice = error_of([&] { r.check_keys(r.parse("name: a\nname: b\n"), allowed, "x"); });
  EXPECT_EQ(twice.line(), 2);
  EXPECT_EQ(twice.message(), "x: key 'name' is given twice");
  const auto missing = error_of([&] { r.required(r.parse("name: a\n"), "steps", "the scenario"); });
  EXPECT_EQ(missing.message(), "the scenario: 'steps' is missing");
}

TEST(YamlReader, ValuesAreCheckedAtTheirNode) {
  const Reader r("t.yaml");
  const YAML::Node n = r.parse("d: 1.5s\nneg: -100ms\nw: 3\nx: 0.25\nb: yes\nm: 30cm\nbad: 2 s\nz: 0\n");
  EXPECT_EQ(r.duration(n["d"], "'d'"), 1500ms);
  EXPECT_EQ(r.signed_duration(n["neg"], "'neg'"), -100ms);
  EXPECT_EQ(r.whole(n["w"], "'w'", 1), 3u);
  EXPECT_DOUBLE_EQ(r.number(n["x"], "'x'"), 0.25);
  EXPECT_TRUE(r.boolean(n["b"], "'b'"));
  EXPECT_DOUBLE_EQ(r.metres(n["m"], "'m'"), 0.3);
  const auto bad = error_of([&] { r.duration(n["bad"], "'bad'"); });
  EXPECT_STREQ(bad.what(),
               "t.yaml:7:6: 'bad' must be a duration with a unit (500ms, 2s, 1.5s), got '2 s'");
  EXPECT_THAT(error_of([&] { r.whole(n["w"], "'w'", 4); }).message(),
              HasSubstr("must be a whole number >= 4, got '3'"));
  EXPECT_THAT(error_of([&] { r.metres(n["z"], "'z'"); }).message(),
              HasSubstr("'z' must be a distance above 0 (0.3m, 30cm, or metres as a number)"));
}

TEST(YamlKit, NumbersAndDescriptions) {
  EXPECT_EQ(parse_number("+1.5"), 1.5);
  EXPECT_EQ(parse_number("-2"), -2.0);
  EXPECT_FALSE(parse_number("+-2"));
  EXPECT_FALSE(parse_number("inf"));
  EXPECT_FALSE(parse_number(""));
  EXPECT_EQ(parse_whole("42"), 42u);
  EXPECT_FALSE(parse_whole("-1"));
  EXPECT_FALSE(parse_whole("99999999999999999999"));
  EXPECT_EQ(describe(YAML::Load("[1, 2]")), "a list of 2");
  EXPECT_EQ(describe(YAML::Load(std::string(50, 'a'))), "'" + std::string(40, 'a') + "...'");
  EXPECT_EQ(closest("raduis_m", {"radius_m", "x_m"}), "radius_m");
  EXPECT_EQ(did_you_mean("qqqq", {"radius_m"}), "");
}

TEST(YamlKit, AFileThatCannotBeReadSaysWhy) {
  EXPECT_STREQ(error_of([] { read_file("/nonexistent/hil/x.yaml", "scenario file"); }).what(),
               "/nonexistent/hil/x.yaml: cannot read the scenario file: No such file or directory");
  const auto dir = std::filesystem::temp_directory_path().string();
  EXPECT_EQ(error_of([&] { read_file(dir, "file"); }).message(),
            "cannot read the file: it is a directory");
}

}  // namespace
}  // namespace hil::config
