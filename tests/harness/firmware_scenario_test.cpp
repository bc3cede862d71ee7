// A scenario whose Arduino car runs a real firmware on the emulated board
// (`car: {kind: arduino, firmware: {elf: FILE}}`, or RunOptions::firmware as
// `hil run --elf` gives it): the key as it loads, its mistakes where they
// are written, what the board cannot do, and runs against hil's test sketch
// (scenarios/firmware/hil_arduino) in virtual time.

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "config/error.hpp"
#include "harness/emulated_car.hpp"
#include "harness/runner.hpp"
#include "harness/scenario_yaml.hpp"
#include "mocks/avr/firmware_source.hpp"
#include "tests/harness/runner_test_support.hpp"
#include "tests/harness/scratch_dir.hpp"

namespace hil::harness {
namespace {

namespace fs = std::filesystem;

const fs::path kTestElf = HIL_TEST_SKETCH_ELF;

// PING, then STATUS; their answers, the test sketch's, are checked by the
// expectations.
const std::string kPingSteps =
    "seed: 1\n"
    "timeout: 10s\n"
    "steps:\n"
    "  - PING\n"
    "  - STATUS\n"
    "  - wait: 300ms\n"
    "expect:\n"
    "  - {label: PONG, received_by_client: ACK, fields: {info: PONG}, count: 1}\n"
    "  - label: the idle status\n"
    "    received_by_client: ACK\n"
    "    fields: {info: \"STATUS:V=140,DIR=stop,MOT:IDLE\"}\n"
    "    count: 1\n";

// A library in a scratch folder: <tmp>/firmware/hil_arduino.elf (the test
// sketch's image), and the scenarios in <tmp>/arduino/. Sketches built here
// go to a cache in the scratch folder.
class FirmwareScenario : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::is_regular_file(kTestElf)) << kTestElf << " is not built";
    fs::create_directories(tmp_ / "firmware");
    fs::create_directories(tmp_ / "arduino");
    fs::copy_file(kTestElf, tmp_ / "firmware" / "hil_arduino.elf");
    const char* cache = std::getenv("XDG_CACHE_HOME");
    if (cache != nullptr) saved_cache_ = cache;
    ::setenv("XDG_CACHE_HOME", (tmp_ / "cache").c_str(), 1);
  }
  void TearDown() override {
    if (saved_cache_)
      ::setenv("XDG_CACHE_HOME", saved_cache_->c_str(), 1);
    else
      ::unsetenv("XDG_CACHE_HOME");
  }

  std::string scenario_file() const { return (tmp_ / "arduino" / "s.yaml").string(); }

  void write(const fs::path& relative, const std::string& text) const {
    fs::create_directories((tmp_ / relative).parent_path());
    std::ofstream(tmp_ / relative) << text;
  }

  /// `name: t`, `car: CAR`, then `rest`.
  Scenario load(const std::string& car, const std::string& rest = kPingSteps) const {
    return parse_scenario_text("name: t\ncar: " + car + "\n" + rest, scenario_file());
  }

  /// The load error of such a scenario, without the file's name, or "" when it loads.
  std::string error_of(const std::string& car, const std::string& rest = kPingSteps) const {
    try {
      load(car, rest);
      return "";
    } catch (const config::ConfigError& e) {
      const std::string what = e.what();
      return what.starts_with(scenario_file() + ":") ? what.substr(scenario_file().size() + 1)
                                                     : what;
    }
  }

  hil::test::ScratchDir scratch_{"hil-firmware-scenario"};
  const fs::path& tmp_ = scratch_.path();
  std::optional<std::string> saved_cache_;
};

const std::string kElfCar = "{kind: arduino, firmware: {elf: ../firmware/hil_arduino.elf}}";

// Steps that arm `behaviour` (a `car:` step's value) after the PING.
std::string steps_arming(const std::string& behaviour) {
  return "steps:\n  - PING\n  - car: " + behaviour + "\n  - STATUS\n";
}

// How many frames of `kind` the client put on the line.
std::size_t client_sent(const ScenarioOutcome& o, const std::string& kind) {
  std::size_t n = 0;
  for (const auto& r : test::of(o, RecordKind(WireKind::frame))) {
    if (r.data.value("stage", "") == "sent" && r.data.value("dir", "") == "to_car" &&
        r.data.value("frame", "") == kind)
      ++n;
  }
  return n;
}

std::string failures(const ScenarioOutcome& o) {
  std::string out = o.error;
  for (const auto& s : o.steps)
    if (!s.ok) out += "\nstep " + s.text + ": " + s.reason;
  for (const auto& e : o.expectations)
    if (!e.passed) out += "\n" + e.label + ": " + e.message;
  return out;
}

TEST_F(FirmwareScenario, TheCarMapLoadsTheImageAndThePinMap) {
  const Scenario s = load(kElfCar);
  ASSERT_TRUE(s.firmware.has_value());
  EXPECT_EQ(fs::weakly_canonical(s.firmware->elf),
            fs::weakly_canonical(tmp_ / "firmware" / "hil_arduino.elf"));
  EXPECT_EQ(s.firmware->pins, mocks::avr::default_pin_map());
  EXPECT_FALSE(load("arduino").firmware.has_value());

  // A pin map file beside the scenario: its wiring replaces the default's.
  write("arduino/pins.yaml", "sonar: {trigger: D9, echo: D10}\n");
  const Scenario wired =
      load("{kind: arduino, firmware: {elf: ../firmware/hil_arduino.elf, pins: pins.yaml}}");
  ASSERT_TRUE(wired.firmware.has_value());
  ASSERT_TRUE(wired.firmware->pins.sonar_trigger.has_value());
  EXPECT_EQ(wired.firmware->pins.sonar_trigger->name, "D9");
  EXPECT_EQ(wired.firmware->pins.left, mocks::avr::default_pin_map().left);
}

TEST_F(FirmwareScenario, MistakesInTheFirmwareMapAreRefusedWhereTheyAreWritten) {
  EXPECT_EQ(
      error_of("{kind: logi, firmware: {elf: ../firmware/hil_arduino.elf}}", "steps: [connect]\n"),
      "2:29: 'firmware' runs on the emulated Arduino board, and this scenario's car is "
      "LOGI (docs/firmware.md)");
  EXPECT_EQ(error_of("{kind: arduino, replay: ../c.ndjson, firmware: {elf: x.elf}}"),
            "2:53: 'firmware' and 'replay' do not go together: the car either runs the "
            "firmware or plays the capture");
  EXPECT_EQ(error_of("{kind: arduino, firmware: ../firmware/hil_arduino.elf}"),
            "2:32: 'firmware' is a map: {sketch: FILE.ino} or {elf: FILE.elf}, with an optional "
            "pins: FILE");
  EXPECT_EQ(error_of("{kind: arduino, firmware: {pins: p.yaml}}"),
            "2:32: 'firmware' is a map: {sketch: FILE.ino} or {elf: FILE.elf}, with an optional "
            "pins: FILE");
  const std::string typo = error_of("{kind: arduino, firmware: {skecth: a.ino}}");
  EXPECT_TRUE(typo.starts_with("2:33: 'firmware': unknown key 'skecth'")) << typo;
  EXPECT_NE(typo.find("did you mean 'sketch'?"), std::string::npos) << typo;
  write("firmware/a/a.ino", "void setup() {}\nvoid loop() {}\n");
  EXPECT_EQ(error_of("{kind: arduino, firmware: {sketch: ../firmware/a/a.ino, elf: "
                     "../firmware/hil_arduino.elf}}"),
            "2:67: 'firmware' takes 'sketch' or 'elf', not both");
  const std::string missing = error_of("{kind: arduino, firmware: {elf: ../firmware/none.elf}}");
  EXPECT_TRUE(missing.starts_with("2:38: ")) << missing;
  EXPECT_NE(missing.find("does not exist"), std::string::npos) << missing;
}

TEST_F(FirmwareScenario, AnImageTheBoardCannotRunIsRefusedAtItsLine) {
  write("firmware/not.elf", "not an ELF file\n");
  const std::string bad = error_of("{kind: arduino,\n  firmware: {elf: ../firmware/not.elf}}");
  EXPECT_TRUE(bad.starts_with("3:19: ")) << bad;
  EXPECT_NE(bad.find("not.elf"), std::string::npos) << bad;
}

TEST_F(FirmwareScenario, ASketchThatDoesNotCompileIsRefusedWithTheCompilersError) {
  write("firmware/broken/broken.ino",
        "void setup() {\n  Serial.begin(9600);\n}\n\nvoid loop() {\n  no_such_function(42);\n}\n");
  const std::string e =
      error_of("{kind: arduino,\n  firmware:\n    {sketch: ../firmware/broken/broken.ino}}");
  EXPECT_TRUE(e.starts_with("4:14: the sketch does not build: ")) << e;
  EXPECT_NE(e.find("broken.ino:6"), std::string::npos) << e;
  EXPECT_NE(e.find("no_such_function"), std::string::npos) << e;
}

TEST_F(FirmwareScenario, APinMapFilesErrorIsReportedAtItsOwnLine) {
  write("arduino/pins.yaml", "motors:\n  left: {pwm: D4}\n");
  const std::string e =
      error_of("{kind: arduino, firmware: {elf: ../firmware/hil_arduino.elf, pins: pins.yaml}}");
  EXPECT_NE(e.find("pins.yaml:2:"), std::string::npos) << e;
  EXPECT_NE(e.find("D4"), std::string::npos) << e;
}

TEST_F(FirmwareScenario, BehavioursTheBoardCannotActOnAreRefusedAtTheBehaviour) {
  const std::string why =
      " needs the behavioural mock, and the firmware (car: firmware:) runs on the emulated "
      "board as it is: only send and close act on it (docs/firmware.md)";
  EXPECT_EQ(error_of(kElfCar, steps_arming("{reject: V}")),
            "5:10: step 2: a `reject` behaviour" + why);
  EXPECT_EQ(error_of(kElfCar, steps_arming("{ignore: {match: PING, for: 1s}}")),
            "5:10: step 2: an `ignore` behaviour" + why);
  EXPECT_EQ(error_of(kElfCar, steps_arming("fault")), "5:10: step 2: a `fault` behaviour" + why);
  EXPECT_EQ(error_of(kElfCar, steps_arming("{mute_telemetry: 2s}")),
            "5:10: step 2: a `mute-telemetry` behaviour" + why);
  EXPECT_EQ(error_of(kElfCar, "steps:\n  - PING\nschedule:\n  - {at: 1s, car: clear_fault}\n"),
            "6:19: schedule 1: a `clear-fault` behaviour" + why);
  EXPECT_EQ(error_of(kElfCar, "reply_latency: 20ms\nsteps:\n  - PING\n"),
            "3:16: 'reply_latency' has no effect on the firmware (car: firmware:): the emulated "
            "board's answers take the chip's own time");
  // What acts on the link in front of the board loads.
  EXPECT_EQ(error_of(kElfCar, steps_arming("{send: \"^00|NACK|BAD_CS*0F$\"}")), "");
  EXPECT_EQ(error_of(kElfCar, steps_arming("close")), "");
  // And the behavioural mock takes them all.
  EXPECT_EQ(error_of("arduino", steps_arming("{reject: V}")), "");
}

TEST_F(FirmwareScenario, TheFirmwareAnswersTheScenariosRequests) {
  const Scenario s = load(kElfCar);
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_TRUE(o.passed()) << failures(o);
  // The board boots 66 ms after the port opens: the PING written at once
  // is lost and sent again after the client's 0.6 s timeout. The
  // behavioural mock answers the first.
  EXPECT_EQ(client_sent(o, "PING"), 2u);
  const ScenarioOutcome mock = run_scenario(load("arduino"));
  EXPECT_TRUE(mock.passed()) << failures(mock);
  EXPECT_EQ(client_sent(mock, "PING"), 1u);
}

TEST_F(FirmwareScenario, RunOptionsPutTheFirmwareInEveryArduinoCar) {
  RunOptions options;
  options.firmware = mocks::avr::resolve_firmware({.elf = kTestElf});
  options.firmware_given = "--elf robot.elf";
  const ScenarioOutcome o = run_scenario(load("arduino"), options);
  EXPECT_FALSE(o.was_skipped()) << o.skipped;
  EXPECT_TRUE(o.passed()) << failures(o);
  EXPECT_EQ(client_sent(o, "PING"), 2u) << "the behavioural mock answered, not the board";
}

TEST_F(FirmwareScenario, RunOptionsSkipWhatTheBoardCannotPlay) {
  RunOptions options;
  options.firmware = mocks::avr::resolve_firmware({.elf = kTestElf});
  options.firmware_given = "--elf robot.elf";
  const auto reason = [&](const Scenario& s) { return skip_reason(s, options).value_or(""); };

  EXPECT_EQ(reason(load("logi", "steps: [connect]\n")),
            "its car is logi and --elf robot.elf runs on the emulated Arduino board");
  EXPECT_EQ(reason(load("arduino", steps_arming("{reject: V}"))),
            "it arms a `reject` behaviour (step 2, line 5), which needs the behavioural mock: "
            "--elf robot.elf runs on the emulated board as it is (docs/firmware.md)");
  EXPECT_EQ(reason(load("arduino", "teardown:\n  - car: {ignore: PING}\nsteps: [PING]\n")),
            "it arms an `ignore` behaviour (teardown step 1, line 4), which needs the "
            "behavioural mock: --elf robot.elf runs on the emulated board as it is "
            "(docs/firmware.md)");
  EXPECT_EQ(reason(load("arduino", "reply_latency: 20ms\nsteps: [PING]\n")),
            "it sets reply_latency: 20ms, which the emulated board does not take (its answers "
            "take the chip's own time): --elf robot.elf runs on the emulated board as it is "
            "(docs/firmware.md)");
  Scenario recorded = load("arduino");
  recorded.replay = mocks::ReplaySpec{};
  recorded.replay->path = "car.ndjson";
  EXPECT_EQ(reason(recorded),
            "its car plays the capture car.ndjson (car: replay:), not --elf "
            "robot.elf");
  // Sending bytes and closing the connection act on the link: they run.
  EXPECT_EQ(reason(load("arduino", steps_arming("close"))), "");
  EXPECT_EQ(reason(load("arduino")), "");

  // A skipped scenario is not run; its outcome says why.
  const ScenarioOutcome o = run_scenario(load("arduino", steps_arming("{reject: V}")), options);
  EXPECT_TRUE(o.was_skipped());
  EXPECT_TRUE(o.passed());
  EXPECT_TRUE(o.timeline.records().empty());
}

TEST(EmulatedBoard, OnlyLinkLevelBehavioursActOnIt) {
  EXPECT_TRUE(acts_on_emulated_board(mocks::SendBytes{}));
  EXPECT_TRUE(acts_on_emulated_board(mocks::CloseConnection{}));
  EXPECT_FALSE(acts_on_emulated_board(mocks::Reject{}));
  EXPECT_FALSE(acts_on_emulated_board(mocks::Ignore{}));
  EXPECT_FALSE(acts_on_emulated_board(mocks::MuteTelemetry{}));
  EXPECT_FALSE(acts_on_emulated_board(mocks::EnterFault{}));
  EXPECT_FALSE(acts_on_emulated_board(mocks::ClearFault{}));
}

}  // namespace
}  // namespace hil::harness
