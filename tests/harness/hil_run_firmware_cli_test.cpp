// hil run --sketch / --elf / --pins as QA and CI use them: every Arduino
// scenario's car runs the firmware on the emulated board, what the board
// cannot play is skipped with the reason, the repro command carries the
// option, and a sketch that does not build stops the run before it starts.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "tests/apps/hil_cli_support.hpp"
#include "tests/harness/scratch_dir.hpp"

namespace hil::test {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kElf = HIL_TEST_SKETCH_ELF;

// A scratch folder for scenario files and the sketch cache (so a run never
// builds into the user's own cache).
class HilRunFirmware : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::is_regular_file(kElf)) << kElf << " is not built";
    const char* cache = std::getenv("XDG_CACHE_HOME");
    if (cache != nullptr) saved_cache_ = cache;
    ::setenv("XDG_CACHE_HOME", (tmp() / "cache").c_str(), 1);
  }
  void TearDown() override {
    if (saved_cache_)
      ::setenv("XDG_CACHE_HOME", saved_cache_->c_str(), 1);
    else
      ::unsetenv("XDG_CACHE_HOME");
  }

  const fs::path& tmp() const { return scratch_.path(); }

  /// Writes `text` to `relative` in the scratch folder; its path.
  std::string write(const std::string& relative, const std::string& text) const {
    const fs::path path = tmp() / relative;
    fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
    return path.string();
  }

  /// An Arduino scenario: PING, then `expect`.
  std::string arduino_scenario(const std::string& name, const std::string& expect) const {
    return write("arduino/" + name + ".yaml", "name: " + name +
                                                  "\ncar: arduino\nseed: 7\ntimeout: 10s\n"
                                                  "steps:\n  - PING\n  - wait: 200ms\n"
                                                  "expect:\n" +
                                                  expect);
  }

  ScratchDir scratch_{"hil-run-firmware"};
  std::optional<std::string> saved_cache_;
};

const std::string kPonged = "  - {label: PONG, received_by_client: ACK, fields: {info: PONG}}\n";

TEST_F(HilRunFirmware, EveryArduinoScenarioRunsTheFirmware) {
  const std::string file = arduino_scenario("ping", kPonged);
  expect_run({.args = "run " + file + " --elf " + kElf + " -v",
              .exit_code = 0,
              .contains = {"] PASS ping (seed 7)", "1 passed, 0 failed"}});
  // The emulated board boots when the port opens: the PING written at once
  // is lost and sent again after the client's 0.6 s timeout; the
  // behavioural mock answers the first one.
  const std::string once =
      arduino_scenario("once", kPonged + "  - {label: one PING, sent_by_client: PING, count: 1}\n");
  expect_run({.args = "run " + once, .exit_code = 0, .contains = {"1 passed, 0 failed"}});
  expect_run({.args = "run " + once + " --elf " + kElf,
              .exit_code = 1,
              .contains = {"expected exactly 1 'client sent PING'", "found 2"}});
}

TEST_F(HilRunFirmware, AFailuresReproCommandCarriesTheFirmware) {
  const std::string file =
      arduino_scenario("silent", "  - {label: no answer, never: {received_by_client: ACK}}\n");
  expect_run(
      {.args = "run " + file + " --elf " + kElf,
       .exit_code = 1,
       .contains = {"repeat: hil run " + file + " --seed 7 --elf " + kElf, "0 passed, 1 failed"}});
  const std::string pins = write("pins.yaml", "sonar: {trigger: D9, echo: D10}\n");
  expect_run(
      {.args = "run " + file + " --elf " + kElf + " --pins " + pins,
       .exit_code = 1,
       .contains = {"repeat: hil run " + file + " --seed 7 --elf " + kElf + " --pins " + pins}});
}

TEST_F(HilRunFirmware, WhatTheBoardCannotPlayIsSkippedWithTheReason) {
  const std::string given = "--elf " + kElf;
  const auto r = run_hil(
      "run scenarios/arduino/arduino-nack-busy-reject.yaml "
      "scenarios/arduino/arduino-reply-latency.yaml "
      "scenarios/logi/logi-buttons.yaml " +
      given);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("0 passed, 0 failed, 3 skipped"));
  EXPECT_THAT(r.output,
              HasSubstr("SKIP arduino-nack-busy-reject (scenarios/arduino/"
                        "arduino-nack-busy-reject.yaml): it arms a `reject` behaviour (step 2, "
                        "line 22), which needs the behavioural mock: " +
                        given + " runs on the emulated board as it is (docs/firmware.md)"));
  EXPECT_THAT(r.output, HasSubstr("arduino-reply-latency.yaml): it sets reply_latency: 20ms, "
                                  "which the emulated board does not take"));
  EXPECT_THAT(r.output, HasSubstr("logi-buttons.yaml): its car is logi and " + given +
                                  " runs on the emulated Arduino board"));
}

TEST_F(HilRunFirmware, ASketchIsBuiltOnceAndRun) {
  const std::string file = arduino_scenario("ping", kPonged);
  const std::string sketch = "scenarios/firmware/hil_arduino/hil_arduino.ino";
  expect_run({.args = "run " + file + " --sketch " + sketch,
              .exit_code = 0,
              .contains = {"1 passed, 0 failed"}});
  // Built into the cache the environment names, and found there the next time.
  EXPECT_FALSE(fs::is_empty(tmp() / "cache" / "hil" / "firmware"));
  const std::string failing =
      arduino_scenario("silent", "  - {label: no answer, never: {received_by_client: ACK}}\n");
  expect_run({.args = "run " + failing + " --sketch " + sketch,
              .exit_code = 1,
              .contains = {"repeat: hil run " + failing + " --seed 7 --sketch " + sketch}});
}

TEST_F(HilRunFirmware, ASketchThatDoesNotCompileIsAUsageError) {
  const std::string file = arduino_scenario("ping", kPonged);
  const std::string sketch = write("broken/broken.ino",
                                   "void setup() {\n  Serial.begin(9600);\n}\n\nvoid loop() {\n"
                                   "  no_such_function(42);\n}\n");
  expect_run({.args = "run " + file + " --sketch " + sketch,
              .exit_code = 2,
              .contains = {"hil run: --sketch: " + sketch + ": does not compile", "broken.ino:6",
                           "no_such_function"},
              .lacks = {"passed", "PING"}});
}

TEST_F(HilRunFirmware, MalformedFirmwareOptionsAreUsageErrors) {
  const std::string file = arduino_scenario("ping", kPonged);
  expect_run(says("run " + file + " --pins pins.yaml", 2, {"--pins needs --sketch or --elf"}));
  expect_run(says("run " + file + " --elf " + kElf + " --sketch a.ino", 2, {"--elf"}));
  expect_run(says("run " + file + " --elf " + kElf + " --replay car.ndjson", 2,
                  {"--replay and --elf do not go together"}));
  expect_run(says("run " + file + " --elf " + tmp().string() + "/none.elf", 2,
                  {"hil run: --elf: ", tmp().string() + "/none.elf"}));
  const std::string pins = write("pins.yaml", "motors:\n  left: {pwm: D4}\n");
  expect_run(says("run " + file + " --elf " + kElf + " --pins " + pins, 2,
                  {"hil run: --pins: " + pins + ":2:", "D4"}));
}

}  // namespace
}  // namespace hil::test
