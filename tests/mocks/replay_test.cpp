// A recorded car as a mock, in virtual time: captures built by hand (a
// probe's exchanges with their times), replayed to a client that writes
// its own requests; what comes back, when, and what the replay counts.

#include "mocks/replay.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "link/capture/probe_capture.hpp"
#include "mocks/car.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/common/car_profile.hpp"
#include "protocol/logi/codec.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"

namespace hil::mocks::test {
namespace {

namespace arduino = protocol::arduino;
namespace logi = protocol::logi;
using link::CaptureRecorder;
using link::ExchangeKind;
using link::milliseconds;

std::string stat_frame(int distance_cm) {
  logi::Status status;
  status.speed_percent = 50;
  status.distance_cm = distance_cm;
  return logi::encode_text(logi::Message{status});
}

// A LOGI probe's capture: connected at 0 ms; MD:MAN written at 120 ms and
// answered at 145 ms; SP:050 at 220 ms answered FB:SP:0 (not what the mock
// would say) at 260 ms; a frame with a wrong checksum at 300 ms that the
// car ignored; then a telemetry exchange. STAT every 100 ms from 50 ms to
// 950 ms, its DIS counting up so each frame can be told apart.
link::Capture logi_capture() {
  CaptureRecorder r({"logi-probe/1", "logi", "guide", "tcp://car:9000", 0});
  int next_stat = 0;
  const auto stats_until = [&](int ms) {
    for (; 50 + 100 * next_stat <= ms; ++next_stat)
      r.received(at_ms(50 + 100 * next_stat), protocol::to_bytes(stat_frame(100 + next_stat)));
  };
  r.begin_exchange(at_ms(0), "connect", ExchangeKind::connect, "the car takes a connection");
  r.opened(at_ms(0), "probe", "tcp://car:9000");
  stats_until(100);
  r.begin_exchange(at_ms(100), "manual", ExchangeKind::command, "MD:MAN");
  r.sent(at_ms(120), protocol::to_bytes(logi::frame_text("MD:MAN")));
  r.received(at_ms(145), protocol::to_bytes(logi::frame_text("FB:MD:1")));
  stats_until(200);
  r.begin_exchange(at_ms(200), "speed", ExchangeKind::command, "SP:050");
  r.sent(at_ms(220), protocol::to_bytes(logi::frame_text("SP:050")));
  stats_until(250);
  r.received(at_ms(260), protocol::to_bytes(logi::frame_text("FB:SP:0")));
  r.begin_exchange(at_ms(280), "bad checksum", ExchangeKind::error, "ignored");
  r.sent(at_ms(300), protocol::to_bytes("LOGI:SP:050:00#"));
  stats_until(340);
  r.begin_exchange(at_ms(340), "telemetry", ExchangeKind::telemetry, "STAT");
  stats_until(1000);
  r.end_exchange(at_ms(1000));
  return r.take();
}

/// What the client saw: each frame, its kind and when it arrived.
struct Seen {
  link::Time at{0};
  std::string kind;
  std::string text;
};

/// A replayed car driven directly in virtual time.
class ReplayRig {
 public:
  explicit ReplayRig(link::Capture capture, Unmatched unmatched = Unmatched::mock,
                     CarKind kind = CarKind::logi, FirmwareConfigs configs = {})
      : world_(sim::WorldDef{sim::default_warehouse_arena()}),
        vehicle_(world_.add_vehicle(vehicle_preset(kind))),
        firmware_(world_, vehicle_, kind, std::make_shared<const link::Capture>(std::move(capture)),
                  unmatched, configs, [this](const std::string& line) { log_.push_back(line); }) {
    splitter_ = firmware_.adapter()->splitter_for(link::Direction::to_client, false);
  }

  void connect(link::Time at) {
    run_until(at);
    firmware_.connect(at);
    collect(at);
  }
  void disconnect(link::Time at) {
    run_until(at);
    firmware_.disconnect(at);
    splitter_ = firmware_.adapter()->splitter_for(link::Direction::to_client, false);
  }
  void write(link::Time at, std::string_view bytes) {
    run_until(at);
    firmware_.receive(at, protocol::ByteView(protocol::to_bytes(bytes)));
    collect(at);
  }
  /// Wakes the firmware whenever it asks, up to `t`.
  void run_until(link::Time t) {
    for (int guard = 0; guard < 100000; ++guard) {
      const auto due = firmware_.next_wakeup();
      if (!due || *due > t) return;
      ASSERT_GE(*due, now_) << "a wakeup in the past";
      now_ = *due;
      firmware_.wake(now_);
      collect(now_);
    }
    FAIL() << "the firmware does not stop asking to wake";
  }

  /// The frames seen of `kind` (all but STAT when empty) since the last look.
  std::vector<Seen> take(std::string_view kind = {}) {
    std::vector<Seen> out;
    std::vector<Seen> rest;
    for (auto& s : seen_) {
      const bool wanted = kind.empty() ? s.kind != "STAT" : s.kind == kind;
      (wanted ? out : rest).push_back(std::move(s));
    }
    seen_ = std::move(rest);
    return out;
  }

  ReplayFirmware& fw() { return firmware_; }
  const std::vector<std::string>& log() const { return log_; }

 private:
  void collect(link::Time at) {
    const auto out = firmware_.take_output();
    std::vector<link::WireFrame> frames;
    splitter_->feed(out, frames);
    for (auto& f : frames)
      seen_.push_back({at, f.kind, std::string(f.raw.begin(), f.raw.end())});
  }

  sim::World world_;
  sim::Vehicle& vehicle_;
  std::vector<std::string> log_;
  ReplayFirmware firmware_;
  std::unique_ptr<link::FrameSplitter> splitter_;
  std::vector<Seen> seen_;
  link::Time now_{0};
};

// ---------------------------------------------------------------- the index

TEST(ReplayIndex, CutsTheCaptureIntoRequestsAnswersAndTelemetry) {
  const ReplayIndex index = index_capture(logi_capture());
  ASSERT_EQ(index.answers.size(), 3u);
  EXPECT_EQ(index.answers[0].kind, "MD:MAN");
  ASSERT_EQ(index.answers[0].replies.size(), 1u);
  EXPECT_EQ(index.answers[0].replies[0].latency, milliseconds(25));
  EXPECT_EQ(index.answers[1].kind, "SP");
  ASSERT_EQ(index.answers[1].replies.size(), 1u);
  EXPECT_EQ(index.answers[1].replies[0].latency, milliseconds(40));
  EXPECT_EQ(index.answers[2].kind, "");  // did not decode
  EXPECT_TRUE(index.answers[2].replies.empty());
  EXPECT_EQ(index.telemetry_kinds, std::set<std::string>{"STAT"});
  ASSERT_EQ(index.telemetry.size(), 1u);
  EXPECT_EQ(index.telemetry[0].frames.size(), 10u);
  EXPECT_EQ(index.telemetry[0].frames.front().first, milliseconds(50));
  EXPECT_EQ(index.telemetry[0].median_period, milliseconds(100));
}

// ---------------------------------------------------------------- LOGI

TEST(ReplayFirmware, TheSameRequestGetsTheRecordedReplyAfterTheRecordedLatency) {
  ReplayRig rig(logi_capture());
  rig.connect(at_ms(1000));
  rig.write(at_ms(1500), logi::frame_text("MD:MAN"));
  rig.run_until(at_ms(1524));
  EXPECT_TRUE(rig.take().empty());
  rig.run_until(at_ms(2000));
  const auto seen = rig.take();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].at, at_ms(1525));
  EXPECT_EQ(seen[0].text, logi::frame_text("FB:MD:1"));
  EXPECT_EQ(rig.fw().replay_stats().exact, 1u);
  EXPECT_EQ(rig.fw().summary(), "replay 1/3 matched, 0 unmatched");
}

TEST(ReplayFirmware, ARequestOfTheSameKindGetsThatKindsRecording) {
  ReplayRig rig(logi_capture());
  rig.connect(at_ms(0));
  // The mock would accept SP:080 (FB:SP:1); the recorded car said FB:SP:0.
  rig.write(at_ms(500), logi::frame_text("SP:080"));
  rig.run_until(at_ms(1000));
  const auto seen = rig.take();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].at, at_ms(540));
  EXPECT_EQ(seen[0].text, logi::frame_text("FB:SP:0"));
  EXPECT_EQ(rig.fw().replay_stats().same_kind, 1u);
  EXPECT_EQ(rig.fw().replay_stats().unmatched, 0u);
}

TEST(ReplayFirmware, ARequestTheCarIgnoredIsIgnoredAndCountsAsMatched) {
  ReplayRig rig(logi_capture());
  rig.connect(at_ms(0));
  rig.write(at_ms(500), "LOGI:SP:050:00#");
  rig.run_until(at_ms(1000));
  EXPECT_TRUE(rig.take().empty());
  EXPECT_EQ(rig.fw().replay_stats().exact, 1u);
  EXPECT_EQ(rig.fw().summary(), "replay 1/3 matched, 0 unmatched");
}

TEST(ReplayFirmware, AnUnrecordedRequestGoesToTheProfilesMock) {
  ReplayRig rig(logi_capture(), Unmatched::mock);
  rig.connect(at_ms(0));
  rig.write(at_ms(500), logi::frame_text("GS:001"));
  rig.run_until(at_ms(3000));
  const auto seen = rig.take();
  ASSERT_EQ(seen.size(), 1u);
  const auto latency = protocol::find_car_profile("logi", "guide").reply_latency;
  EXPECT_EQ(seen[0].at, at_ms(500) + latency);
  EXPECT_EQ(seen[0].text, logi::frame_text("FB:GS:1"));
  EXPECT_EQ(rig.fw().replay_stats().unmatched, 1u);
  EXPECT_EQ(rig.fw().summary(), "replay 0/3 matched, 1 unmatched");
  ASSERT_EQ(rig.log().size(), 1u);
  EXPECT_NE(rig.log()[0].find("GS"), std::string::npos) << rig.log()[0];
  EXPECT_NE(rig.log()[0].find("mock answers"), std::string::npos) << rig.log()[0];
  // Only the recorded STATs: the inner mock's own (every 500 ms) are dropped.
  const auto stats = rig.take("STAT");
  for (const auto& s : stats)
    EXPECT_EQ(std::chrono::duration_cast<milliseconds>(s.at).count() % 100, 50) << s.text;
}

TEST(ReplayFirmware, TheMocksReplyLatencyIsTheCallersWhenSet) {
  FirmwareConfigs configs;
  configs.reply_latency = milliseconds(70);
  ReplayRig rig(logi_capture(), Unmatched::mock, CarKind::logi, configs);
  rig.connect(at_ms(0));
  rig.write(at_ms(500), logi::frame_text("GS:001"));
  // The recorded answers keep their own latency.
  rig.write(at_ms(600), logi::frame_text("MD:MAN"));
  rig.run_until(at_ms(1000));
  const auto seen = rig.take();
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0].at, at_ms(570));
  EXPECT_EQ(seen[0].text, logi::frame_text("FB:GS:1"));
  EXPECT_EQ(seen[1].at, at_ms(625));
}

TEST(ReplayFirmware, AnUnrecordedRequestIsLeftUnansweredWhenSilent) {
  ReplayRig rig(logi_capture(), Unmatched::silent);
  rig.connect(at_ms(0));
  rig.write(at_ms(500), logi::frame_text("GS:001"));
  rig.run_until(at_ms(3000));
  EXPECT_TRUE(rig.take().empty());
  EXPECT_EQ(rig.fw().replay_stats().unmatched, 1u);
  ASSERT_EQ(rig.log().size(), 1u);
  EXPECT_NE(rig.log()[0].find("left unanswered"), std::string::npos) << rig.log()[0];
}

TEST(ReplayFirmware, StatFollowsTheRecordedScheduleFromConnectionThenItsMedianPeriod) {
  ReplayRig rig(logi_capture());
  rig.connect(at_ms(1000));
  rig.run_until(at_ms(2499));
  const auto stats = rig.take("STAT");
  // Recorded at 50, 150, ..., 950 ms after the connection; then every
  // 100 ms (the median), the recorded frames over again.
  ASSERT_EQ(stats.size(), 15u);
  for (std::size_t i = 0; i < stats.size(); ++i) {
    EXPECT_EQ(stats[i].at, at_ms(1050 + 100 * static_cast<int>(i))) << i;
    EXPECT_EQ(stats[i].text, stat_frame(100 + static_cast<int>(i % 10))) << i;
  }
  EXPECT_EQ(rig.fw().replay_stats().telemetry, 15u);
}

TEST(ReplayFirmware, ANewConnectionStartsTheScheduleAgain) {
  ReplayRig rig(logi_capture());
  rig.connect(at_ms(0));
  rig.run_until(at_ms(300));
  rig.disconnect(at_ms(300));
  rig.run_until(at_ms(5000));
  rig.take("STAT");
  rig.connect(at_ms(5000));
  rig.run_until(at_ms(5200));
  const auto stats = rig.take("STAT");
  ASSERT_EQ(stats.size(), 2u);
  EXPECT_EQ(stats[0].at, at_ms(5050));
  EXPECT_EQ(stats[0].text, stat_frame(100));
  EXPECT_EQ(stats[1].at, at_ms(5150));
}

TEST(ReplayFirmware, NothingIsSentWithoutAClient) {
  ReplayRig rig(logi_capture());
  rig.run_until(at_ms(5000));
  EXPECT_TRUE(rig.take("STAT").empty());
  EXPECT_EQ(rig.fw().replay_stats().telemetry, 0u);
}

TEST(ReplayFirmware, TheCarClosingAfterARequestIsReplayedOnTime) {
  // Recorded: after MD:AUTO at 100 ms the car closed the connection at 1,100 ms.
  CaptureRecorder r({"logi-probe/1", "logi", "guide", "tcp://car:9000", 0});
  r.begin_exchange(at_ms(0), "hang up", ExchangeKind::error, "the car closes");
  r.opened(at_ms(0), "probe", "tcp://car:9000");
  r.sent(at_ms(100), protocol::to_bytes(logi::frame_text("MD:AUTO")));
  r.closed(at_ms(1100), {link::LinkClose::By::car, link::CloseMode::graceful, "car closed"});
  r.end_exchange(at_ms(1200));
  ReplayRig rig(r.take());
  rig.connect(at_ms(0));
  rig.write(at_ms(2000), logi::frame_text("MD:AUTO"));
  rig.run_until(at_ms(2999));
  EXPECT_FALSE(rig.fw().take_close().has_value());
  rig.run_until(at_ms(3000));
  EXPECT_EQ(rig.fw().take_close(), std::optional<link::CloseMode>(link::CloseMode::graceful));
}

// ---------------------------------------------------------------- Arduino

std::string arduino_frame(std::uint8_t seq, arduino::Body body) {
  return arduino::encode_text(arduino::Message{seq, std::move(body)}, arduino::Dialect::firmware);
}

// An Arduino probe's capture: the port opened at 0; PING (SEQ 1) written at
// 2,000 ms and answered PONG at 2,012 ms.
link::Capture arduino_capture() {
  CaptureRecorder r({"arduino-probe/1", "arduino", "firmware", "pty:///dev/ttyACM0", 0});
  r.begin_exchange(at_ms(0), "open", ExchangeKind::connect, "the port opens");
  r.opened(at_ms(0), "probe", "pty:///dev/ttyACM0");
  r.begin_exchange(at_ms(1900), "ping", ExchangeKind::command, "PING");
  r.sent(at_ms(2000), protocol::to_bytes(arduino_frame(1, arduino::Ping{})));
  r.received(at_ms(2012), protocol::to_bytes(arduino_frame(1, arduino::Ack{"PONG"})));
  r.end_exchange(at_ms(2100));
  return r.take();
}

TEST(ReplayFirmwareArduino, ThePingGetsThePongAfterTheRecordedLatency) {
  ReplayRig rig(arduino_capture(), Unmatched::mock, CarKind::arduino);
  rig.connect(at_ms(0));
  rig.write(at_ms(300), arduino_frame(1, arduino::Ping{}));
  rig.run_until(at_ms(1000));
  const auto seen = rig.take();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].at, at_ms(312));
  EXPECT_EQ(seen[0].text, arduino_frame(1, arduino::Ack{"PONG"}));
  EXPECT_EQ(rig.fw().replay_stats().exact, 1u);
}

TEST(ReplayFirmwareArduino, AnotherSequenceNumberGetsTheRecordedAnswerWithItsOwn) {
  ReplayRig rig(arduino_capture(), Unmatched::mock, CarKind::arduino);
  rig.connect(at_ms(0));
  rig.write(at_ms(300), arduino_frame(0x2A, arduino::Ping{}));
  rig.run_until(at_ms(1000));
  const auto seen = rig.take();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].at, at_ms(312));
  EXPECT_EQ(seen[0].text, arduino_frame(0x2A, arduino::Ack{"PONG"}));
  EXPECT_EQ(rig.fw().replay_stats().same_kind, 1u);
}

TEST(ReplayFirmwareArduino, AnUnrecordedCommandIsTheMocksOrNobodys) {
  // What the profile's own mock says to V 200, for comparison.
  std::string mock_answer;
  {
    sim::World world(sim::WorldDef{sim::default_warehouse_arena()});
    auto& vehicle = world.add_vehicle(vehicle_preset(CarKind::arduino));
    FirmwareConfigs configs;
    apply_profile(configs, CarKind::arduino, "firmware");
    auto plain = make_firmware(CarKind::arduino, world, vehicle, configs);
    plain->connect(at_ms(0));
    plain->take_output();
    plain->receive(at_ms(300), protocol::to_bytes(arduino_frame(2, arduino::SetSpeed{200})));
    for (auto due = plain->next_wakeup(); due && *due <= at_ms(1000); due = plain->next_wakeup())
      plain->wake(*due);
    const auto out = plain->take_output();
    mock_answer.assign(out.begin(), out.end());
  }
  ASSERT_FALSE(mock_answer.empty());

  ReplayRig mock(arduino_capture(), Unmatched::mock, CarKind::arduino);
  mock.connect(at_ms(0));
  mock.write(at_ms(300), arduino_frame(2, arduino::SetSpeed{200}));
  mock.run_until(at_ms(1000));
  const auto seen = mock.take();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].text, mock_answer);
  EXPECT_EQ(mock.fw().replay_stats().unmatched, 1u);

  ReplayRig silent(arduino_capture(), Unmatched::silent, CarKind::arduino);
  silent.connect(at_ms(0));
  silent.write(at_ms(300), arduino_frame(2, arduino::SetSpeed{200}));
  silent.run_until(at_ms(1000));
  EXPECT_TRUE(silent.take().empty());
  EXPECT_EQ(silent.fw().replay_stats().unmatched, 1u);
  EXPECT_EQ(silent.fw().summary(), "replay 0/1 matched, 1 unmatched");
}

// ---------------------------------------------------------------- MockCar

TEST(MockCarReplay, ReadsTheCaptureFileAndPlaysIt) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("hil-replay-test-" + std::to_string(::getpid()) + ".ndjson");
  {
    auto log = link::open_capture_log(path, link::protocol_adapter("logi", "guide"));
    CaptureRecorder r({"logi-probe/1", "logi", "guide", "tcp://car:9000", 0}, log);
    r.begin_exchange(at_ms(0), "manual", ExchangeKind::command, "MD:MAN");
    r.opened(at_ms(0), "probe", "tcp://car:9000");
    r.sent(at_ms(20), protocol::to_bytes(logi::frame_text("MD:MAN")));
    r.received(at_ms(31), protocol::to_bytes(logi::frame_text("FB:MD:1")));
    r.end_exchange(at_ms(100));
  }
  CarOptions options;
  options.kind = CarKind::logi;
  options.replay = ReplaySpec{path.string(), nullptr, Unmatched::silent, {}};
  MockCar car(std::move(options));
  std::filesystem::remove(path);
  ASSERT_NE(dynamic_cast<ReplayFirmware*>(&car.firmware()), nullptr);
  auto& fw = car.firmware();
  fw.connect(at_ms(0));
  fw.receive(at_ms(10), protocol::to_bytes(logi::frame_text("MD:MAN")));
  EXPECT_EQ(fw.next_wakeup(), std::optional<link::Time>(at_ms(21)));
  fw.wake(at_ms(21));
  const auto out = fw.take_output();
  EXPECT_EQ(std::string(out.begin(), out.end()), logi::frame_text("FB:MD:1"));
}

TEST(MockCarReplay, ACaptureOfAnotherCarIsRefusedByName) {
  CarOptions options;
  options.kind = CarKind::wr8;
  options.replay = ReplaySpec{
      "logi.ndjson", std::make_shared<const link::Capture>(logi_capture()), Unmatched::mock, {}};
  try {
    MockCar car(std::move(options));
    FAIL() << "a LOGI capture played as a WR8 car";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "logi.ndjson is a capture of a logi car, not of a wr8 car");
  }
}

TEST(MockCarReplay, AMissingCaptureFileIsTheReadersError) {
  CarOptions options;
  options.replay = ReplaySpec{"/nonexistent/capture.ndjson", nullptr, Unmatched::mock, {}};
  EXPECT_THROW(MockCar car(std::move(options)), link::CaptureError);
}

}  // namespace
}  // namespace hil::mocks::test
