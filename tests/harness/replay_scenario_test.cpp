// A scenario whose car is a recorded one (`car: {kind: logi, replay: FILE}`):
// the key as it loads, its mistakes where they are written, and a run in
// virtual time in which the reference client gets the recorded answers.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "harness/runner.hpp"
#include "harness/scenario_yaml.hpp"
#include "link/capture/probe_capture.hpp"
#include "protocol/logi/codec.hpp"
#include "tests/harness/runner_test_support.hpp"
#include "tests/harness/scratch_dir.hpp"

namespace hil::harness {
namespace {

namespace fs = std::filesystem;
namespace logi = protocol::logi;
using link::CaptureRecorder;
using link::ExchangeKind;
using test::of;

Time at_ms(int ms) {
  return Time(std::chrono::milliseconds(ms));
}

std::string stat_frame(int distance_cm) {
  logi::Status status;
  status.speed_percent = 50;
  status.distance_cm = distance_cm;
  return logi::encode_text(logi::Message{status});
}

// A library in a scratch folder: <tmp>/captures/car.ndjson, a LOGI car
// recorded refusing MD:MAN (FB:MD:0, 30 ms after the request; the mock
// accepts it) with STAT every 100 ms from 50 ms after the connection, and
// the scenarios in <tmp>/logi/.
class ReplayScenario : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(tmp_ / "captures");
    fs::create_directories(tmp_ / "logi");
    auto log = link::open_capture_log(tmp_ / "captures" / "car.ndjson",
                                      link::protocol_adapter("logi", "guide"));
    CaptureRecorder r({"logi-probe/1", "logi", "guide", "tcp://car:9000", 0}, log);
    r.begin_exchange(at_ms(0), "connect", ExchangeKind::connect, "open");
    r.opened(at_ms(0), "probe", "tcp://car:9000");
    r.received(at_ms(50), protocol::to_bytes(stat_frame(100)));
    r.begin_exchange(at_ms(100), "manual", ExchangeKind::command, "MD:MAN");
    r.sent(at_ms(120), protocol::to_bytes(logi::frame_text("MD:MAN")));
    r.received(at_ms(150), protocol::to_bytes(logi::frame_text("FB:MD:0")));
    r.received(at_ms(150), protocol::to_bytes(stat_frame(101)));
    r.begin_exchange(at_ms(200), "telemetry", ExchangeKind::telemetry, "STAT");
    for (int i = 2; i < 10; ++i)
      r.received(at_ms(50 + 100 * i), protocol::to_bytes(stat_frame(100 + i)));
    r.end_exchange(at_ms(1000));
  }

  std::string scenario_file() const { return (tmp_ / "logi" / "s.yaml").string(); }

  Scenario load(const std::string& car, const std::string& more = "") const {
    const std::string yaml = "name: t\ncar: " + car + "\n" + more +
                             "seed: 1\nsteps:\n  - connect\n  - wait: 1200ms\n  - mode MAN\n";
    return parse_scenario_text(yaml, scenario_file());
  }

  /// The load error of a scenario with this `car:`, or "" when it loads.
  std::string error_of(const std::string& car, const std::string& more = "") const {
    try {
      load(car, more);
      return "";
    } catch (const config::ConfigError& e) {
      return e.what();
    }
  }

  hil::test::ScratchDir scratch_{"hil-replay"};
  const fs::path& tmp_ = scratch_.path();
};

TEST_F(ReplayScenario, TheCarMapLoadsTheCaptureAndItsProfile) {
  const Scenario s = load("{kind: logi, replay: ../captures/car.ndjson, unmatched: silent}");
  EXPECT_EQ(s.car, mocks::CarKind::logi);
  ASSERT_TRUE(s.replay.has_value());
  EXPECT_EQ(fs::path(s.replay->path), (tmp_ / "captures" / "car.ndjson").lexically_normal());
  ASSERT_NE(s.replay->capture, nullptr);
  EXPECT_EQ(s.replay->capture->exchanges.size(), 3u);
  EXPECT_EQ(s.replay->unmatched, mocks::Unmatched::silent);
  EXPECT_EQ(s.profile, "guide");
  // Without the map, no replay; the map's unmatched defaults to mock.
  EXPECT_FALSE(load("logi").replay.has_value());
  EXPECT_EQ(load("{kind: logi, replay: ../captures/car.ndjson}").replay->unmatched,
            mocks::Unmatched::mock);
}

TEST_F(ReplayScenario, MistakesAreRefusedWhereTheyAreWritten) {
  EXPECT_NE(error_of("{kind: wr8, replay: ../captures/car.ndjson}")
                .find("is a capture of a logi car, not of a wr8 car"),
            std::string::npos);
  EXPECT_NE(error_of("{kind: logi, replay: ../captures/none.ndjson}").find("does not exist"),
            std::string::npos);
  EXPECT_NE(error_of("{kind: logi, replay: ../captures/car.ndjson, unmatched: loud}")
                .find("'unmatched' must be mock or silent"),
            std::string::npos);
  EXPECT_NE(error_of("{kind: logi, unmatched: silent}").find("needs 'replay'"), std::string::npos);
  EXPECT_NE(error_of("{kind: logi, replay: ../captures/car.ndjson}", "profile: firmware\n")
                .find("differs from the capture's, guide"),
            std::string::npos);
  EXPECT_NE(error_of("{kind: logi, replay: ../captures/car.ndjson, colour: red}").find("colour"),
            std::string::npos);
  // A file that is not a capture: the reader's file:line.
  std::ofstream(tmp_ / "captures" / "bad.ndjson") << "{\"event\":\"open\",\"t_ms\":0}\n";
  const std::string bad = error_of("{kind: logi, replay: ../captures/bad.ndjson}");
  EXPECT_NE(bad.find("bad.ndjson:1: not a probe capture"), std::string::npos) << bad;
}

TEST_F(ReplayScenario, TheRunsCarAnswersAsRecordedOnTheRecordedSchedule) {
  const Scenario s = load("{kind: logi, replay: ../captures/car.ndjson, unmatched: silent}");
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.error.empty()) << o.error;
  Time md_at{-1};
  Time connected{-1};
  std::vector<std::pair<Time, std::string>> from_car;
  for (const auto& r : o.timeline.records()) {
    if (r.kind == RecordKind(WireKind::open) && connected < Time{0}) connected = r.at;
    if (r.kind != RecordKind(WireKind::frame) || r.data["stage"] != "sent") continue;
    if (r.data["dir"] == "to_car" && r.data["frame"] == "MD:MAN") md_at = r.at;
    if (r.data["dir"] == "to_client") from_car.emplace_back(r.at, r.data.value("text", ""));
  }
  ASSERT_GE(md_at, Time{0}) << "the client sent no MD:MAN";
  ASSERT_GE(connected, Time{0});
  std::vector<std::pair<Time, std::string>> feedback;
  std::vector<Time> stats;
  for (const auto& [at, text] : from_car) {
    if (text.rfind("LOGI:FB:", 0) == 0) feedback.emplace_back(at, text);
    if (text.rfind("LOGI:STAT", 0) == 0) stats.push_back(at - connected);
  }
  // The recorded refusal, 30 ms after the request reached the car.
  ASSERT_EQ(feedback.size(), 1u);
  EXPECT_EQ(feedback[0].second, logi::frame_text("FB:MD:0"));
  EXPECT_EQ(feedback[0].first - md_at, std::chrono::milliseconds(30));
  // Recorded up to 950 ms, then on at the median 100 ms.
  ASSERT_GE(stats.size(), 12u);
  for (std::size_t i = 0; i < stats.size(); ++i)
    EXPECT_EQ(stats[i], std::chrono::milliseconds(50 + 100 * static_cast<int>(i))) << i;
  // The client is told the car refused manual mode, as the real one did.
  ASSERT_EQ(o.steps.size(), 3u);
  EXPECT_TRUE(o.steps[1].ok);
  EXPECT_FALSE(o.steps[2].ok) << "mode MAN: the recorded car refused it";
}

}  // namespace
}  // namespace hil::harness
