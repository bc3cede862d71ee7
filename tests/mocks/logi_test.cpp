// The LOGI car's mock firmware under the virtual-time driver: every command
// and its feedback, malformed and dropped input, STAT timing and fields,
// manual mecanum motion, the line-following auto mode, the obstacle lock,
// the fault state and scripted behaviours.

#include "mocks/logi.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "protocol/logi/codec.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"

namespace hil::mocks {
namespace {

namespace logi = protocol::logi;
using link::milliseconds;
using link::seconds;
using link::Time;
using logi::Direction;
using logi::Mode;

constexpr double kTolM = 0.005;

/// 4 m x 3 m with walls and nothing else; the car starts in the middle facing +x.
sim::Arena open_floor() {
  sim::Arena a;
  a.name = "open";
  a.start = {2.0, 1.5, 0.0};
  return a;
}

/// 6 m x 1 m: a straight tape along y = 0.5, a parcel on it at x = 2.0
/// (front face at 1.95), station 001 at x = 3.0 beyond it.
sim::Arena corridor() {
  sim::Arena a;
  a.name = "corridor";
  a.width_m = 6.0;
  a.height_m = 1.0;
  a.tapes.push_back(sim::Tape{"line", {{0.2, 0.5}, {5.8, 0.5}}});
  a.obstacles.push_back(sim::BoxObstacle{"parcel", {2.0, 0.5}, 0.1, 0.3, 0});
  a.tags.push_back(sim::RfidTag{"001", {3.0, 0.5}});
  a.start = {0.5, 0.5, 0.0};
  return a;
}

/// A tape that ends at x = 1.5, with station 001 out of reach beyond it.
sim::Arena short_tape() {
  sim::Arena a;
  a.name = "short";
  a.tapes.push_back(sim::Tape{"line", {{0.3, 1.5}, {1.5, 1.5}}});
  a.tags.push_back(sim::RfidTag{"001", {3.5, 1.5}});
  a.start = {0.5, 1.5, 0.0};
  return a;
}

/// A connected client in front of the firmware on mem://, decoding what the car sends.
class Bench {
 public:
  explicit Bench(LogiConfig config = {}, sim::Arena arena = sim::default_warehouse_arena(),
                 sim::VehicleDef vehicle = sim::logi_car())
      : car_(
            std::move(vehicle),
            [config](sim::World& w, sim::Vehicle& v) {
              return std::make_unique<LogiFirmware>(w, v, config);
            },
            {}, sim::WorldDef{std::move(arena)}) {
    client_ = car_.connect();
  }

  /// Sends one well-formed frame now and lets the car handle it at this instant.
  void send(std::string_view payload) { send_raw(logi::frame_text(payload)); }
  void send_raw(std::string_view bytes) {
    client_->write(bytes);
    car_.run_for(link::Duration::zero());
  }
  /// Sends a command and returns the car's answers (payload text, one per
  /// frame, space-separated; empty when there was none).
  std::string ask(std::string_view payload) {
    send(payload);
    return answers();
  }
  std::string ask_raw(std::string_view bytes) {
    send_raw(bytes);
    return answers();
  }
  /// Feedback received since the last look, as payload text.
  std::string answers() {
    take();
    std::string out;
    for (const auto& f : feedback_) {
      if (!out.empty()) out += ' ';
      out += logi::payload_of(f);
    }
    feedback_.clear();
    return out;
  }
  /// STAT frames received since the last look, with their arrival times.
  std::vector<std::pair<Time, logi::Status>> stats() {
    take();
    return std::exchange(stats_, {});
  }
  /// Runs the clock to `t`, collecting frames with the time they arrived.
  void run_until(Time t) {
    while (car_.now() < t) {
      const auto next = car_.executor().next_due();
      car_.run_until(next && *next <= t ? *next : t);
      take();
    }
  }
  void run_for(link::Duration d) { run_until(car_.now() + d); }
  /// Runs in 10 ms slices until `done()` holds or `limit` passes; returns whether it held.
  bool run_until(const std::function<bool()>& done, link::Duration limit) {
    const Time end = car_.now() + limit;
    while (!done()) {
      if (car_.now() >= end) return false;
      run_for(milliseconds(10));
    }
    return true;
  }

  /// Runs until the car is not running (as run_until(done, limit)).
  bool run_until_stopped(link::Duration limit) {
    return run_until([this] { return !state().running; }, limit);
  }
  /// Sets the target station and starts the run, whatever the answers.
  void start_run(std::string_view station) {
    ask("GS:" + std::string(station));
    ask("ST:RUN");
  }

  Time now() const { return car_.now(); }
  LogiFirmware& fw() { return car_.firmware(); }
  const LogiState& state() { return car_.firmware().state(); }
  sim::Vehicle& vehicle() { return car_.vehicle(); }
  sim::Pose pose() { return car_.vehicle().pose(); }
  test::ClientEnd& client() { return *client_; }
  test::VirtualCar<LogiFirmware>& car() { return car_; }
  std::uint64_t decode_errors() const { return decode_errors_; }

 private:
  void take() {
    const auto bytes = client_->take();
    items_.clear();
    decoder_.feed(bytes, items_);
    for (auto& item : items_) {
      if (auto* f = std::get_if<protocol::Frame<logi::Message>>(&item)) {
        if (auto* fb = std::get_if<logi::Feedback>(&f->message)) feedback_.push_back(*fb);
        if (auto* st = std::get_if<logi::Status>(&f->message)) stats_.emplace_back(now(), *st);
      } else {
        ++decode_errors_;
      }
    }
  }

  test::VirtualCar<LogiFirmware> car_;
  std::shared_ptr<test::ClientEnd> client_;
  logi::Decoder decoder_;
  std::vector<logi::Item> items_;
  std::vector<logi::Feedback> feedback_;
  std::vector<std::pair<Time, logi::Status>> stats_;
  std::uint64_t decode_errors_ = 0;
};

using test::at_ms;

/// Sends each command in turn and expects its answer.
void expect_answers(Bench& b,
                    std::initializer_list<std::pair<std::string_view, std::string_view>> asked) {
  for (const auto& [command, answer] : asked)
    EXPECT_EQ(b.ask(command), answer) << command;
}

double speed_of(const sim::Twist& t) {
  return std::hypot(t.vx_mps, t.vy_mps);
}

// ---------------------------------------------------------------- boot and STAT

TEST(LogiFirmware, BootsInAutoAtHalfSpeedWithNoStation) {
  Bench b;
  EXPECT_EQ(b.fw().protocol(), "logi");
  EXPECT_EQ(b.state().speed_percent, 50);
  EXPECT_EQ(b.state().mode, Mode::automatic);
  EXPECT_EQ(b.state().station, 0);
  EXPECT_FALSE(b.state().station_armed);
  EXPECT_FALSE(b.state().running);
  EXPECT_EQ(b.state().manual, Direction::stop);
  EXPECT_EQ(b.fw().summary(), "AUTO IDLE STA 000 SP 50 DIS 232");
}

TEST(LogiFirmware, StatComesEvery500MsOnTheGridWhileConnected) {
  Bench b;  // connected at 0
  b.run_until(at_ms(500) - link::Duration(1));
  EXPECT_TRUE(b.stats().empty());
  b.run_until(at_ms(500));
  auto first = b.stats();
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].first, at_ms(500));
  b.run_until(at_ms(5000));
  const auto later = b.stats();
  ASSERT_EQ(later.size(), 9u);
  for (std::size_t i = 0; i < later.size(); ++i) {
    EXPECT_EQ(later[i].first, at_ms(1000 + 500 * static_cast<int>(i)));
  }
  EXPECT_EQ(b.decode_errors(), 0u);
}

TEST(LogiFirmware, ABootOffsetShiftsTheStatAndControlGridsByItself) {
  // A car switched on 137 ms in: STAT at 137 + k * 500 ms, and the control
  // loop, while it has work, at 137 + k * 10 ms; nothing at the zero grid.
  LogiConfig config;
  config.boot_offset = link::milliseconds(137);
  Bench b(config);  // connected at 0
  b.run_until(at_ms(137) - link::Duration(1));
  EXPECT_TRUE(b.stats().empty());
  b.run_until(at_ms(2000));
  const auto stats = b.stats();
  ASSERT_EQ(stats.size(), 4u);
  for (std::size_t i = 0; i < stats.size(); ++i)
    EXPECT_EQ(stats[i].first, at_ms(137 + 500 * static_cast<int>(i)));
  // Driving, the control loop wakes on its own grid, offset alike.
  ASSERT_EQ(b.ask("MD:MAN"), "FB:MD:1");
  ASSERT_EQ(b.ask("MV:FWD"), "FB:MV:1");
  const auto wake = b.fw().next_wakeup();
  ASSERT_TRUE(wake.has_value());
  EXPECT_EQ((*wake - at_ms(137)) % link::milliseconds(10), link::Duration::zero())
      << link::to_ms(*wake) << " ms";
  EXPECT_EQ(b.decode_errors(), 0u);
}

TEST(LogiFirmware, ABootOffsetOutsideOneStatPeriodIsRefused) {
  LogiConfig config;
  config.boot_offset = link::milliseconds(501);
  EXPECT_THROW(Bench{config}, std::invalid_argument);
  config.boot_offset = link::milliseconds(-1);
  EXPECT_THROW(Bench{config}, std::invalid_argument);
}

TEST(LogiFirmware, AClientConnectingBetweenGridPointsGetsItsFirstStatAtTheNextOne) {
  Bench b;
  b.client().pipe->close();
  b.run_until(at_ms(1234));
  EXPECT_FALSE(b.fw().connected());
  auto late = b.car().connect();  // connected at 1234 ms
  b.car().run_until(at_ms(1500) - link::Duration(1));
  EXPECT_TRUE(late->received.empty());
  b.car().run_until(at_ms(1500));
  logi::Decoder decoder;
  std::vector<logi::Item> items;
  decoder.feed(late->take(), items);
  ASSERT_EQ(items.size(), 1u);
  const auto& frame = std::get<protocol::Frame<logi::Message>>(items[0]);
  EXPECT_TRUE(std::holds_alternative<logi::Status>(frame.message));
}

TEST(LogiFirmware, StatFieldsAtRestOnTheWarehouseStart) {
  Bench b;
  b.run_until(at_ms(500));
  const auto stats = b.stats();
  ASSERT_EQ(stats.size(), 1u);
  // The beam's right edge (15 degrees) meets the south wall 0.6 m / sin 15 = 2.32 m
  // from the nose, nearer than the east wall straight ahead (2.66 m); the
  // tape is centred between H3 and H2.
  const logi::Status expected{.speed_percent = 50,
                              .station = 0,
                              .running = false,
                              .mode = Mode::automatic,
                              .manual = Direction::stop,
                              .distance_cm = 232,
                              .track_mask = 0b0110,
                              .deviation = 0,
                              .obstacle = false,
                              .rpm = {0, 0, 0, 0}};
  EXPECT_EQ(stats[0].second, expected);
  EXPECT_EQ(logi::encode_text(stats[0].second),
            logi::frame_text("STAT:SP:050,STA:000,RUN:0,MODE:AUTO,MAN:STOP,DIS:232,TRK:0110,DEV:0,"
                             "OBS:0,RPM:0:0:0:0"));
}

TEST(LogiFirmware, StatFieldsFollowTheSimulationWhileStrafing) {
  Bench b({}, open_floor());
  b.ask("MD:MAN");
  b.ask("SP:100");
  EXPECT_EQ(b.ask("MV:LEFT"), "FB:MV:1");
  b.run_until(at_ms(1000));
  const auto stats = b.stats();
  ASSERT_EQ(stats.size(), 2u);
  const logi::Status& s = stats[1].second;
  EXPECT_EQ(s.mode, Mode::manual);
  EXPECT_EQ(s.manual, Direction::left);
  EXPECT_EQ(s.speed_percent, 100);
  EXPECT_FALSE(s.running);
  // 12.5 rad/s = 119.4 RPM; strafing left turns LR and RF forward, LF and RR back.
  EXPECT_EQ(s.rpm, (std::array<int, 4>{119, -119, 119, -119}));
  // Facing +x at x = 2.0: the sonar sees the east wall 4.0 - 2.14 m away.
  EXPECT_NEAR(s.distance_cm, 186, 1);
  EXPECT_EQ(s.track_mask, 0);
  EXPECT_EQ(s.deviation, 0);
  EXPECT_GT(b.pose().y_m, 1.5 + 0.3);
}

TEST(LogiFirmware, StatKeepsStationAndRunFromTheRun) {
  Bench b;
  b.start_run("002");
  b.run_until(at_ms(1000));
  const auto stats = b.stats();
  ASSERT_EQ(stats.size(), 2u);
  EXPECT_EQ(stats[1].second.station, 2);
  EXPECT_TRUE(stats[1].second.running);
  EXPECT_EQ(stats[1].second.mode, Mode::automatic);
  // Driving straight at 0.25 m/s: every wheel at 6.25 rad/s = 59.7 RPM.
  EXPECT_EQ(stats[1].second.rpm, (std::array<int, 4>{60, 60, 60, 60}));
}

TEST(LogiFirmware, NoStatWithoutAClient) {
  Bench b;
  b.client().pipe->close();
  b.run_until(at_ms(2000));
  EXPECT_FALSE(b.fw().connected());
  EXPECT_EQ(b.fw().stats().frames_out, 0u);
  EXPECT_EQ(b.fw().next_wakeup(), std::nullopt);  // idle and alone: nothing to do
}

// ---------------------------------------------------------------- commands

TEST(LogiFirmware, SpeedAcceptsZeroToHundred) {
  Bench b;
  EXPECT_EQ(b.ask("SP:030"), "FB:SP:1");
  EXPECT_EQ(b.state().speed_percent, 30);
  EXPECT_EQ(b.ask("SP:000"), "FB:SP:1");
  EXPECT_EQ(b.state().speed_percent, 0);
  EXPECT_EQ(b.ask("SP:100"), "FB:SP:1");
  EXPECT_EQ(b.state().speed_percent, 100);
}

TEST(LogiFirmware, MalformedSpeedIsRefusedAndLeavesTheSpeed) {
  Bench b;
  b.ask("SP:030");
  for (const char* bad : {"SP:101", "SP:150", "SP:abc", "SP:50", "SP:0500", "SP:", "SP:-10"}) {
    EXPECT_EQ(b.ask(bad), "FB:SP:0") << bad;
  }
  EXPECT_EQ(b.state().speed_percent, 30);
  EXPECT_EQ(b.fw().stats().bad_frames, 7u);
  EXPECT_EQ(b.fw().stats().frames_in, 1u);
}

TEST(LogiFirmware, TheSourcesPresetFramesGetTheirFeedback) {
  Bench b;
  EXPECT_EQ(b.ask_raw("LOGI:SP:030:D5#"), "FB:SP:1");
  EXPECT_EQ(b.ask_raw("LOGI:SP:050:D7#"), "FB:SP:1");
  EXPECT_EQ(b.ask_raw("LOGI:SP:080:DA#"), "FB:SP:1");
  EXPECT_EQ(b.ask_raw("LOGI:GS:001:CA#"), "FB:GS:1");
  EXPECT_EQ(b.ask_raw("LOGI:GS:002:CB#"), "FB:GS:1");
  EXPECT_EQ(b.ask_raw("LOGI:MV:FWD:23#"), "FB:MV:0");  // AUTO mode
  EXPECT_EQ(b.ask_raw("LOGI:ST:RUN:3B#"), "FB:ST:1");
  EXPECT_EQ(b.ask_raw("LOGI:ST:STOP:8C#"), "FB:ST:1");
  EXPECT_EQ(b.ask_raw("LOGI:MD:MAN:0C#"), "FB:MD:1");
  for (const char* frame :
       {"LOGI:MV:FWD:23#", "LOGI:MV:BWD:1F#", "LOGI:MV:LEFT:6D#", "LOGI:MV:RIGHT:C0#",
        "LOGI:MV:LF:D4#", "LOGI:MV:RF:DA#", "LOGI:MV:LB:D0#", "LOGI:MV:RB:D6#", "LOGI:MV:CW:DC#",
        "LOGI:MV:CCW:1F#", "LOGI:MV:STOP:88#"}) {
    EXPECT_EQ(b.ask_raw(frame), "FB:MV:1") << frame;
  }
  EXPECT_EQ(b.ask_raw("LOGI:MD:AUTO:69#"), "FB:MD:1");
  EXPECT_EQ(b.fw().stats().frames_in, 21u);
  EXPECT_EQ(b.fw().stats().bad_frames, 0u);
}

TEST(LogiFirmware, StationAcceptsTheConfiguredListOnly) {
  Bench b;
  EXPECT_EQ(b.ask("GS:001"), "FB:GS:1");
  EXPECT_EQ(b.state().station, 1);
  EXPECT_EQ(b.ask("GS:002"), "FB:GS:1");
  EXPECT_EQ(b.state().station, 2);
  expect_answers(b, {
                        {"GS:003", "FB:GS:0"},
                        {"GS:000", "FB:GS:0"},
                        {"GS:999", "FB:GS:0"},
                        {"GS:x", "FB:GS:0"},
                        {"GS:1", "FB:GS:0"},
                    });
  EXPECT_EQ(b.state().station, 2);

  Bench seven(LogiConfig{.stations = {1, 2, 7}});
  EXPECT_EQ(seven.ask("GS:007"), "FB:GS:1");
  EXPECT_EQ(seven.state().station, 7);
}

TEST(LogiFirmware, ModeSwitchesBothWaysAndRefusesNonsense) {
  Bench b;
  EXPECT_EQ(b.ask("MD:MAN"), "FB:MD:1");
  EXPECT_EQ(b.state().mode, Mode::manual);
  // MAN again (already there), then AUTO.
  expect_answers(b, {{"MD:MAN", "FB:MD:1"}, {"MD:AUTO", "FB:MD:1"}});
  EXPECT_EQ(b.state().mode, Mode::automatic);
  expect_answers(b, {{"MD:HALF", "FB:MD:0"}, {"MD:auto", "FB:MD:0"}});
  EXPECT_EQ(b.state().mode, Mode::automatic);
}

TEST(LogiFirmware, EveryMoveIsRefusedInAutoAndNothingMoves) {
  Bench b;
  for (const Direction d : logi::kAllDirections) {
    EXPECT_EQ(b.ask("MV:" + std::string(logi::to_string(d))), "FB:MV:0") << logi::to_string(d);
  }
  b.run_for(seconds(1));
  EXPECT_EQ(b.state().manual, Direction::stop);
  EXPECT_NEAR(b.pose().x_m, 1.2, 1e-6);
  EXPECT_EQ(b.fw().next_wakeup(), at_ms(1500));  // only STAT: the control loop sleeps
}

TEST(LogiFirmware, MalformedMoveAndRunAreRefused) {
  Bench b;
  b.ask("MD:MAN");
  expect_answers(b, {
                        {"MV:UP", "FB:MV:0"},
                        {"MV:fwd", "FB:MV:0"},
                        {"ST:GO", "FB:ST:0"},
                        {"ST:", "FB:ST:0"},
                    });
  EXPECT_EQ(b.state().manual, Direction::stop);
}

TEST(LogiFirmware, RunNeedsAutoModeAndAStation) {
  Bench b;
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:0");  // no station yet
  EXPECT_FALSE(b.state().running);
  b.ask("GS:001");
  b.ask("MD:MAN");
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:0");  // manual mode
  EXPECT_FALSE(b.state().running);
  b.ask("MD:AUTO");
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:1");
  EXPECT_TRUE(b.state().running);
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:1");  // already running: still fine
  EXPECT_EQ(b.fw().summary(), "AUTO RUN STA 001 SP 50 DIS 232");
}

TEST(LogiFirmware, StopAlwaysSucceeds) {
  Bench b;
  EXPECT_EQ(b.ask("ST:STOP"), "FB:ST:1");
  b.ask("MD:MAN");
  EXPECT_EQ(b.ask("ST:STOP"), "FB:ST:1");
}

// ---------------------------------------------------------------- bad input

TEST(LogiFirmware, ABadChecksumIsDroppedAndTheConnectionStays) {
  Bench b;
  EXPECT_EQ(b.ask_raw("LOGI:SP:030:D6#"), "");
  EXPECT_EQ(b.state().speed_percent, 50);
  EXPECT_EQ(b.fw().stats().bad_frames, 1u);
  EXPECT_TRUE(b.fw().connected());
  EXPECT_FALSE(b.client().closed.has_value());
  EXPECT_EQ(b.ask_raw("LOGI:SP:030:D5#"), "FB:SP:1");
  // A malformed payload behind a bad checksum is noise too: no answer.
  EXPECT_EQ(b.ask_raw("LOGI:SP:abc:00#"), "");
  EXPECT_EQ(b.ask_raw("LOGI:SP:030:ZZ#"), "");
  EXPECT_EQ(b.fw().stats().bad_frames, 3u);
  b.run_until(at_ms(500));
  EXPECT_EQ(b.stats().size(), 1u);  // telemetry goes on
}

TEST(LogiFirmware, ALowercaseChecksumIsDroppedUnlessConfigured) {
  Bench strict;
  EXPECT_EQ(strict.ask_raw("LOGI:SP:030:d5#"), "");
  EXPECT_EQ(strict.fw().stats().bad_frames, 1u);
  Bench lenient(LogiConfig{.accept_lowercase_checksum = true});
  EXPECT_EQ(lenient.ask_raw("LOGI:SP:030:d5#"), "FB:SP:1");
  EXPECT_EQ(lenient.state().speed_percent, 30);
}

TEST(LogiFirmware, GarbageUnknownCodesAndOversizedRunsAreDroppedAndCounted) {
  Bench b;
  EXPECT_EQ(b.ask_raw("hello"), "");
  expect_answers(b, {
                        {"ZZ:1", ""},
                        {"SPEED:050", ""},
                        {"NOCOLON", ""},
                    });
  EXPECT_EQ(b.fw().stats().bad_frames, 4u);
  // 256 bytes at most are held: the first 256 come out as one oversized piece...
  EXPECT_EQ(b.ask_raw("LOGI:" + std::string(400, 'A')), "");
  EXPECT_EQ(b.fw().stats().bad_frames, 5u);
  // ...and the rest, with a CR LF, when the next header shows where it ends.
  EXPECT_EQ(b.ask_raw("\r\n" + logi::frame_text("SP:040")), "FB:SP:1");
  EXPECT_EQ(b.fw().stats().bad_frames, 6u);
  EXPECT_EQ(b.state().speed_percent, 40);
  EXPECT_TRUE(b.fw().connected());
}

TEST(LogiFirmware, TheCarsOwnFramesFromTheClientAreDropped) {
  Bench b;
  EXPECT_EQ(b.ask_raw(logi::encode_text(logi::Feedback{logi::Command::sp, true})), "");
  EXPECT_EQ(b.ask_raw(logi::encode_text(logi::Status{})), "");
  EXPECT_EQ(b.ask("STAT:SP:abc"), "");
  EXPECT_EQ(b.fw().stats().bad_frames, 3u);
  EXPECT_EQ(b.fw().stats().frames_in, 0u);
}

TEST(LogiFirmware, SplitAndStickyFramesAreEachAnsweredOnce) {
  Bench b;
  const std::string frame = logi::frame_text("SP:070");
  b.send_raw(frame.substr(0, 6));
  EXPECT_EQ(b.answers(), "");
  b.send_raw(frame.substr(6));
  EXPECT_EQ(b.answers(), "FB:SP:1");
  EXPECT_EQ(b.ask_raw(logi::frame_text("MD:MAN") + logi::frame_text("MV:FWD") +
                      logi::frame_text("GS:005")),
            "FB:MD:1 FB:MV:1 FB:GS:0");
  EXPECT_EQ(b.state().speed_percent, 70);
}

// ---------------------------------------------------------------- manual motion

struct ManualCase {
  Direction direction;
  double dx_m, dy_m, dheading_rad;
};

TEST(LogiFirmware, ManualDirectionsMoveTheCarAsCommanded) {
  // SP 50: wheels at 6.25 rad/s. One second from rest with the 1 m/s^2 ramp:
  // straight and strafe 0.25 m/s -> 0.219 m; diagonals 0.177 m/s along 45
  // degrees -> 0.114 m each way; rotation 1.389 rad/s with the 8 rad/s^2 ramp -> 1.268 rad.
  const double straight = 0.25 - 0.25 * 0.25 / 2;
  const double v_diag = 0.25 / std::sqrt(2.0);
  const double diag = (v_diag - v_diag * v_diag / 2) / std::sqrt(2.0);
  const double wz = 0.04 * 6.25 / 0.18;
  const double turn = wz - wz * wz / (2 * 8.0);
  const std::vector<ManualCase> cases = {
      {Direction::fwd, straight, 0, 0},  {Direction::bwd, -straight, 0, 0},
      {Direction::left, 0, straight, 0}, {Direction::right, 0, -straight, 0},
      {Direction::lf, diag, diag, 0},    {Direction::rf, diag, -diag, 0},
      {Direction::lb, -diag, diag, 0},   {Direction::rb, -diag, -diag, 0},
      {Direction::ccw, 0, 0, turn},      {Direction::cw, 0, 0, -turn},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(std::string(logi::to_string(c.direction)));
    Bench b({}, open_floor());
    b.ask("MD:MAN");
    const sim::Pose start = b.pose();
    EXPECT_EQ(b.ask("MV:" + std::string(logi::to_string(c.direction))), "FB:MV:1");
    EXPECT_EQ(b.state().manual, c.direction);
    b.run_for(seconds(1));
    const sim::Pose end = b.pose();
    EXPECT_NEAR(end.x_m - start.x_m, c.dx_m, kTolM);
    EXPECT_NEAR(end.y_m - start.y_m, c.dy_m, kTolM);
    EXPECT_NEAR(sim::wrap_angle(end.heading_rad - start.heading_rad), c.dheading_rad, 0.02);
  }
}

TEST(LogiFirmware, DiagonalsRunAt45Degrees) {
  Bench b({}, open_floor());
  b.ask("MD:MAN");
  b.ask("MV:LF");
  b.run_for(seconds(1));
  const sim::Twist v = b.vehicle().velocity();
  EXPECT_NEAR(v.vx_mps, v.vy_mps, 1e-4);
  EXPECT_NEAR(speed_of(v), 0.25 / std::sqrt(2.0), 1e-3);
}

TEST(LogiFirmware, MoveStopAndANewMoveTakeOverAtOnce) {
  Bench b({}, open_floor());
  b.ask("MD:MAN");
  b.ask("MV:FWD");
  b.run_for(seconds(1));
  EXPECT_EQ(b.ask("MV:BWD"), "FB:MV:1");
  b.run_for(seconds(1));
  EXPECT_LT(b.vehicle().velocity().vx_mps, -0.2);
  EXPECT_EQ(b.ask("MV:STOP"), "FB:MV:1");
  EXPECT_EQ(b.state().manual, Direction::stop);
  b.run_for(milliseconds(300));  // 0.25 m/s comes down at 1 m/s^2 in 0.25 s
  const sim::Pose rest = b.pose();
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  b.run_for(seconds(1));
  EXPECT_NEAR(b.pose().x_m, rest.x_m, 1e-9);
  // At rest the control loop sleeps; only the next STAT is due.
  EXPECT_EQ(b.fw().next_wakeup(), (b.now() / milliseconds(500) + 1) * milliseconds(500));
}

TEST(LogiFirmware, SpeedChangesApplyToTheMotionUnderWay) {
  Bench b({}, open_floor());
  b.ask("MD:MAN");
  b.ask("SP:020");
  b.ask("MV:FWD");
  b.run_for(seconds(1));
  EXPECT_NEAR(b.vehicle().velocity().vx_mps, 0.10, 1e-3);
  EXPECT_EQ(b.ask("SP:080"), "FB:SP:1");
  EXPECT_EQ(b.state().manual, Direction::fwd);
  b.run_for(seconds(1));
  EXPECT_NEAR(b.vehicle().velocity().vx_mps, 0.40, 1e-3);
  b.ask("SP:000");  // the motion stays commanded, at zero speed
  b.run_for(seconds(1));
  EXPECT_NEAR(b.vehicle().velocity().vx_mps, 0.0, 1e-6);
  EXPECT_EQ(b.state().manual, Direction::fwd);
}

TEST(LogiFirmware, RotationRateScalesWithSpeed) {
  for (const int sp : {20, 100}) {
    Bench b({}, open_floor());
    b.ask("MD:MAN");
    b.ask("SP:" + std::string(sp < 100 ? "0" : "") + std::to_string(sp));
    b.ask("MV:CW");
    b.run_for(seconds(1));
    // wz = r * w / (lx + ly) with w = 12.5 rad/s * SP / 100: 159 degrees/s at 100 %.
    EXPECT_NEAR(b.vehicle().velocity().wz_radps, -0.04 * 12.5 * sp / 100 / 0.18, 1e-3) << sp;
  }
}

TEST(LogiFirmware, StopCommandAndModeSwitchHaltManualMotion) {
  Bench b({}, open_floor());
  b.ask("MD:MAN");
  b.ask("MV:RIGHT");
  b.run_for(milliseconds(500));
  EXPECT_EQ(b.ask("ST:STOP"), "FB:ST:1");
  EXPECT_EQ(b.state().manual, Direction::stop);
  b.run_for(milliseconds(500));
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);

  b.ask("MV:FWD");
  b.run_for(milliseconds(500));
  EXPECT_EQ(b.ask("MD:AUTO"), "FB:MD:1");
  EXPECT_EQ(b.state().manual, Direction::stop);
  b.run_for(milliseconds(500));
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
}

// ---------------------------------------------------------------- auto mode

TEST(LogiFirmware, AutoRunFromTheStartStopsOnStation001AndNeedsGsAgain) {
  Bench b;
  expect_answers(b, {
                        {"MD:AUTO", "FB:MD:1"},
                        {"GS:001", "FB:GS:1"},
                        {"ST:RUN", "FB:ST:1"},
                    });
  ASSERT_TRUE(b.run_until_stopped(seconds(10)));
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::arrived);
  EXPECT_EQ(b.state().arrivals, 1u);
  b.run_for(seconds(1));
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  // Station 001 is at (2.0, 0.6); the car reads it 5 cm early and brakes from 0.25 m/s.
  EXPECT_NEAR(b.pose().x_m, 2.0, 0.05);
  EXPECT_NEAR(b.pose().y_m, 0.6, 0.02);
  const auto stats = b.stats();
  ASSERT_FALSE(stats.empty());
  EXPECT_TRUE(stats.front().second.running);
  EXPECT_FALSE(stats.back().second.running);
  EXPECT_EQ(stats.back().second.station, 1);  // STA still shows where it went
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:0");      // arrival used the station up
  EXPECT_FALSE(b.state().station_armed);
  EXPECT_EQ(b.ask("GS:002"), "FB:GS:1");
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:1");
  ASSERT_TRUE(b.run_until_stopped(seconds(40)));
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::arrived);
  EXPECT_NEAR(b.pose().y_m, 2.4, 0.02);
  EXPECT_NEAR(b.pose().x_m, 2.0, 0.1);
}

TEST(LogiFirmware, AutoRunTo002PassesStation001WithoutStopping) {
  Bench b;
  b.start_run("002");
  bool passed_001 = false;
  ASSERT_TRUE(b.run_until(
      [&] {
        if (b.state().tag == std::optional<std::string>("001")) {
          passed_001 = true;
          EXPECT_TRUE(b.state().running);
        }
        return !b.state().running;
      },
      seconds(40)));
  EXPECT_TRUE(passed_001);
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::arrived);
  EXPECT_EQ(b.state().arrivals, 1u);
  EXPECT_NEAR(b.pose().x_m, 2.0, 0.1);
  EXPECT_NEAR(b.pose().y_m, 2.4, 0.02);
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:0");
}

TEST(LogiFirmware, TheFollowerIsStableFrom20To100Percent) {
  for (const int sp : {20, 40, 60, 80, 100}) {
    SCOPED_TRACE(sp);
    Bench b;
    b.ask("SP:" + std::string(sp < 100 ? "0" : "") + std::to_string(sp));
    b.start_run("002");
    const sim::Tape& tape = b.car().world().arena().tapes.at(0);
    double worst_m = 0;
    int lost_ticks = 0;
    ASSERT_TRUE(b.run_until(
        [&] {
          const sim::Vec2 row = b.pose().to_arena({0.12, 0});
          worst_m = std::max(worst_m, tape.distance_to_centerline(row));
          if (b.vehicle().line_tracker().lost()) ++lost_ticks;
          return !b.state().running;
        },
        seconds(60)));
    EXPECT_EQ(b.state().last_run_end, LogiRunEnd::arrived);
    EXPECT_LT(worst_m, 0.02);  // the tracker row never strays past the tape's edge
    EXPECT_EQ(lost_ticks, 0);
    EXPECT_EQ(b.vehicle().contacts(), 0);
  }
}

TEST(LogiFirmware, ARunStartedOnItsStationsTagGoesRoundTheLoop) {
  Bench b;
  b.start_run("001");
  ASSERT_TRUE(b.run_until_stopped(seconds(10)));
  b.run_for(seconds(1));
  ASSERT_EQ(b.vehicle().rfid(), std::optional<std::string>("001"));  // stopped on the tag
  b.ask("GS:001");
  const Time start = b.now();
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:1");
  ASSERT_TRUE(b.run_until_stopped(seconds(60)));
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::arrived);
  EXPECT_EQ(b.state().arrivals, 2u);
  EXPECT_GT(b.now() - start, seconds(25));  // 7.7 m of tape at 0.25 m/s or less
  EXPECT_NEAR(b.pose().x_m, 2.0, 0.05);
  EXPECT_NEAR(b.pose().y_m, 0.6, 0.02);
}

TEST(LogiFirmware, StopPausesARunThatRunResumes) {
  Bench b;
  b.start_run("002");
  b.run_for(seconds(2));
  EXPECT_EQ(b.ask("ST:STOP"), "FB:ST:1");
  EXPECT_FALSE(b.state().running);
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::stopped);
  EXPECT_TRUE(b.state().station_armed);
  b.run_for(seconds(1));
  const sim::Pose held = b.pose();
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  b.run_for(seconds(1));
  EXPECT_EQ(b.pose(), held);
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:1");  // no new GS needed after a stop
  ASSERT_TRUE(b.run_until_stopped(seconds(40)));
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::arrived);
  EXPECT_NEAR(b.pose().y_m, 2.4, 0.02);
}

TEST(LogiFirmware, SpeedZeroHoldsARunInPlaceUntilSpeedComesBack) {
  Bench b;
  b.ask("SP:000");
  b.ask("GS:001");
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:1");
  b.run_for(seconds(3));
  EXPECT_TRUE(b.state().running);
  EXPECT_NEAR(b.pose().x_m, 1.2, 1e-6);
  EXPECT_EQ(b.ask("SP:060"), "FB:SP:1");  // takes effect on the run under way
  ASSERT_TRUE(b.run_until_stopped(seconds(10)));
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::arrived);
}

TEST(LogiFirmware, StationCannotChangeDuringARun) {
  Bench b;
  b.start_run("002");
  b.run_for(milliseconds(500));
  EXPECT_EQ(b.ask("GS:001"), "FB:GS:0");
  EXPECT_EQ(b.state().station, 2);
  EXPECT_TRUE(b.state().running);
}

TEST(LogiFirmware, ManualModeTakesOverFromARun) {
  Bench b;
  b.start_run("002");
  b.run_for(milliseconds(500));
  EXPECT_EQ(b.ask("MV:STOP"), "FB:MV:0");  // MV is refused in AUTO, STOP included
  EXPECT_TRUE(b.state().running);
  EXPECT_EQ(b.ask("MD:MAN"), "FB:MD:1");
  EXPECT_FALSE(b.state().running);
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::mode_change);
  EXPECT_EQ(b.state().manual, Direction::stop);
  b.run_for(milliseconds(500));
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  EXPECT_EQ(b.ask("MV:BWD"), "FB:MV:1");
}

TEST(LogiFirmware, LosingTheLineEndsTheRunAfterTheTimeout) {
  Bench b({}, short_tape());
  b.start_run("001");
  ASSERT_TRUE(b.run_until_stopped(seconds(10)));
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::line_lost);
  EXPECT_EQ(b.state().track_mask, 0);
  b.run_for(seconds(1));
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  EXPECT_LT(b.pose().x_m, 1.5 + 0.3);  // 0.5 s blind at 0.25 m/s, then braking

  // The station is still set, so ST:RUN is taken; with no tape under the
  // tracker the run ends exactly one timeout later.
  b.run_until(at_ms(20000));
  const Time start = b.now();
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:1");
  b.run_until(start + milliseconds(490));
  EXPECT_TRUE(b.state().running);
  b.run_until(start + milliseconds(500));
  EXPECT_FALSE(b.state().running);
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::line_lost);
}

// ---------------------------------------------------------------- obstacle lock

TEST(LogiFirmware, TheObstacleLockHaltsAnAutoRunAndLetsItGoWhenClear) {
  Bench b({}, corridor());
  b.start_run("001");
  ASSERT_TRUE(b.run_until([&] { return b.state().obstacle; }, seconds(10)));
  EXPECT_TRUE(b.state().running);
  b.run_for(seconds(2));
  EXPECT_TRUE(b.state().obstacle);
  EXPECT_TRUE(b.state().running);
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  EXPECT_LT(b.state().distance_cm, 20);
  EXPECT_EQ(b.vehicle().contacts(), 0);  // halted short of the parcel
  EXPECT_LT(b.pose().x_m + 0.14, 1.95);
  const auto stats = b.stats();
  ASSERT_FALSE(stats.empty());
  EXPECT_TRUE(stats.back().second.obstacle);
  EXPECT_TRUE(stats.back().second.running);
  EXPECT_EQ(stats.back().second.rpm, (std::array<int, 4>{0, 0, 0, 0}));
  EXPECT_EQ(b.fw().summary(),
            "AUTO RUN STA 001 SP 50 DIS " + std::to_string(b.state().distance_cm) + " OBS");

  // The parcel is carried off: put the car on the tape beyond it.
  b.vehicle().place({2.3, 0.5, 0.0});
  ASSERT_TRUE(b.run_until([&] { return !b.state().obstacle; }, milliseconds(100)));
  ASSERT_TRUE(b.run_until_stopped(seconds(10)));
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::arrived);
  EXPECT_NEAR(b.pose().x_m, 3.0, 0.05);
}

TEST(LogiFirmware, TheObstacleLockHasAClearHysteresis) {
  Bench b({}, corridor());
  b.ask("MD:MAN");
  b.ask("MV:FWD");
  ASSERT_TRUE(b.run_until([&] { return b.state().obstacle; }, seconds(10)));
  b.run_for(milliseconds(500));
  EXPECT_EQ(b.state().manual, Direction::fwd);  // the command stands; the lock holds it
  // Nose 22 cm from the parcel: above the stop distance, below stop + hysteresis.
  b.vehicle().place({1.95 - 0.22 - 0.14, 0.5, 0.0});
  b.run_for(milliseconds(200));
  EXPECT_TRUE(b.state().obstacle);
  EXPECT_EQ(b.state().distance_cm, 22);
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  // 27 cm: clear again, and the car drives on until 20 cm stops it once more.
  b.vehicle().place({1.95 - 0.27 - 0.14, 0.5, 0.0});
  ASSERT_TRUE(b.run_until([&] { return !b.state().obstacle; }, milliseconds(100)));
  ASSERT_TRUE(b.run_until([&] { return b.state().obstacle; }, seconds(5)));
  EXPECT_EQ(b.vehicle().contacts(), 0);
}

TEST(LogiFirmware, TheObstacleLockGuardsOnlyMotionWithAForwardPart) {
  LogiConfig config;
  for (const auto& [dir, locks] : std::vector<std::pair<Direction, bool>>{
           {Direction::fwd, true},
           {Direction::lf, true},
           {Direction::rf, true},
           {Direction::bwd, false},
           {Direction::left, false},
           {Direction::right, false},
           {Direction::lb, false},
           {Direction::rb, false},
           {Direction::cw, false},
           {Direction::ccw, false},
       }) {
    SCOPED_TRACE(std::string(logi::to_string(dir)));
    Bench b(config, corridor());
    b.vehicle().place({1.95 - 0.15 - 0.14, 0.5, 0.0});  // nose 15 cm from the parcel
    b.ask("MD:MAN");
    b.run_for(milliseconds(100));
    EXPECT_FALSE(b.state().obstacle);  // standing still: no lock
    const sim::Pose before = b.pose();
    b.ask("MV:" + std::string(logi::to_string(dir)));
    EXPECT_EQ(b.state().obstacle, locks);
    b.run_for(milliseconds(300));
    const sim::Pose after = b.pose();
    const bool moved = std::abs(after.x_m - before.x_m) > 1e-3 ||
                       std::abs(after.y_m - before.y_m) > 1e-3 ||
                       std::abs(after.heading_rad - before.heading_rad) > 1e-3;
    EXPECT_EQ(moved, !locks);
    b.ask("MV:STOP");
    EXPECT_FALSE(b.state().obstacle);
  }
}

TEST(LogiFirmware, TheStopDistanceIsConfigurable) {
  LogiConfig config;
  config.obstacle_stop_cm = 50;
  Bench b(config, corridor());
  b.ask("MD:MAN");
  b.ask("MV:FWD");
  ASSERT_TRUE(b.run_until([&] { return b.state().obstacle; }, seconds(10)));
  EXPECT_LT(b.state().distance_cm, 50);
  EXPECT_GE(b.state().distance_cm, 45);
}

// ---------------------------------------------------------------- fault and behaviours

TEST(LogiFirmware, TheFaultStateStopsTheCarAndRefusesMotion) {
  Bench b;
  b.start_run("002");
  b.fw().arm(Behaviour{"", When{at_ms(1000), "", 1}, EnterFault{}});
  b.run_until(at_ms(1000));
  EXPECT_TRUE(b.fw().in_fault());
  EXPECT_FALSE(b.state().running);
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::fault);
  b.run_for(milliseconds(500));
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  EXPECT_EQ(b.fw().summary().substr(0, 10), "AUTO FAULT");
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:0");
  EXPECT_EQ(b.ask("SP:080"), "FB:SP:1");  // settings still work
  expect_answers(b, {
                        {"GS:001", "FB:GS:1"},
                        {"ST:STOP", "FB:ST:1"},
                        {"MD:MAN", "FB:MD:1"},
                        {"MV:FWD", "FB:MV:0"},
                        {"MV:CW", "FB:MV:0"},
                        {"MV:STOP", "FB:MV:1"},
                    });
  const sim::Pose held = b.pose();
  b.run_for(seconds(1));
  EXPECT_EQ(b.pose(), held);
  const auto stats = b.stats();
  ASSERT_FALSE(stats.empty());
  EXPECT_FALSE(stats.back().second.running);
  EXPECT_EQ(stats.back().second.rpm, (std::array<int, 4>{0, 0, 0, 0}));

  b.fw().arm(Behaviour{"", When{}, ClearFault{}});
  b.run_for(milliseconds(1));
  EXPECT_FALSE(b.fw().in_fault());
  EXPECT_EQ(b.state().manual, Direction::stop);  // nothing restarts by itself
  expect_answers(b, {
                        {"MV:FWD", "FB:MV:1"},
                        {"MD:AUTO", "FB:MD:1"},
                        {"ST:RUN", "FB:ST:1"},
                    });
}

TEST(LogiFirmware, ARejectAnswersNegativelyWithoutEffect) {
  Bench b;
  b.fw().arm(Behaviour{"", When{}, Reject{"SP", 1}});
  b.run_for(milliseconds(1));
  EXPECT_EQ(b.ask("SP:030"), "FB:SP:0");
  EXPECT_EQ(b.state().speed_percent, 50);
  EXPECT_EQ(b.ask("SP:030"), "FB:SP:1");
  EXPECT_EQ(b.state().speed_percent, 30);

  b.ask("MD:MAN");
  b.fw().arm(Behaviour{"", When{}, Reject{"MV", 1}});
  b.run_for(milliseconds(1));
  EXPECT_EQ(b.ask("MV:FWD"), "FB:MV:0");
  b.run_for(milliseconds(500));
  EXPECT_EQ(b.state().manual, Direction::stop);
  EXPECT_NEAR(b.pose().x_m, 1.2, 1e-6);

  b.ask("MD:AUTO");
  b.ask("GS:001");
  b.fw().arm(Behaviour{"", When{}, Reject{"ST:RUN", 1}});
  b.run_for(milliseconds(1));
  EXPECT_EQ(b.ask("ST:STOP"), "FB:ST:1");  // another kind
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:0");
  EXPECT_FALSE(b.state().running);
  EXPECT_EQ(b.fw().stats().rejected, 3u);
}

TEST(LogiFirmware, AnIgnoreSwallowsCommandsWithoutAnswerOrEffect) {
  Bench b;
  b.fw().arm(Behaviour{"", When{}, Ignore{"GS", 2, std::nullopt}});
  b.run_for(milliseconds(1));
  EXPECT_EQ(b.ask("GS:001"), "");
  EXPECT_EQ(b.ask("GS:x"), "");  // a malformed GS is swallowed too
  EXPECT_EQ(b.state().station, 0);
  EXPECT_EQ(b.ask("SP:030"), "FB:SP:1");
  EXPECT_EQ(b.ask("GS:001"), "FB:GS:1");
  EXPECT_EQ(b.fw().stats().ignored, 2u);
}

TEST(LogiFirmware, MutedTelemetryStillAnswersCommands) {
  Bench b;
  b.fw().arm(Behaviour{"", When{at_ms(600), "", 1}, MuteTelemetry{milliseconds(1000)}});
  b.run_until(at_ms(1200));
  EXPECT_EQ(b.ask("SP:040"), "FB:SP:1");
  b.run_until(at_ms(2500));
  const auto stats = b.stats();
  // 500 went out; 1000 and 1500 fell in the mute (600..1600); 2000 and 2500 did not.
  ASSERT_EQ(stats.size(), 3u);
  EXPECT_EQ(stats[0].first, at_ms(500));
  EXPECT_EQ(stats[1].first, at_ms(2000));
  EXPECT_EQ(stats[2].first, at_ms(2500));
  EXPECT_EQ(stats[1].second.speed_percent, 40);
}

TEST(LogiFirmware, ScriptedFramesAndHangUpsReachTheClient) {
  Bench b;
  b.fw().arm(Behaviour{"", When{std::nullopt, "SP", 1},
                       SendBytes{protocol::to_bytes(logi::frame_text("FB:SP:0"))}});
  EXPECT_EQ(b.ask("SP:030"), "FB:SP:1 FB:SP:0");
  b.fw().arm(Behaviour{"", When{std::nullopt, "MD", 1}, CloseConnection{}});
  EXPECT_EQ(b.ask("MD:MAN"), "FB:MD:1");
  b.run_for(milliseconds(5));
  EXPECT_TRUE(b.client().closed.has_value());
  EXPECT_FALSE(b.fw().connected());
}

// ---------------------------------------------------------------- disconnect

TEST(LogiFirmware, MotionGoesOnWhenTheClientLeavesByDefault) {
  Bench b({}, open_floor());
  b.ask("MD:MAN");
  b.ask("MV:LEFT");
  b.run_for(milliseconds(500));
  b.client().pipe->close();
  b.run_for(milliseconds(10));
  EXPECT_FALSE(b.fw().connected());
  const sim::Pose left_at = b.pose();
  b.run_for(seconds(1));
  EXPECT_NEAR(b.pose().y_m - left_at.y_m, 0.25, 0.01);  // still strafing
  EXPECT_EQ(b.state().manual, Direction::left);
  EXPECT_GE(b.car().world().time(), b.now() - milliseconds(10));
}

TEST(LogiFirmware, StopOnDisconnectHaltsManualMotionAndEndsARun) {
  LogiConfig config;
  config.stop_on_disconnect = true;
  {
    Bench b(config, open_floor());
    b.ask("MD:MAN");
    b.ask("MV:LEFT");
    b.run_for(milliseconds(500));
    b.client().pipe->close();
    b.run_for(milliseconds(500));
    EXPECT_EQ(b.state().manual, Direction::stop);
    EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  }
  {
    Bench b(config);
    b.start_run("002");
    b.run_for(milliseconds(500));
    b.client().pipe->close();
    b.run_for(milliseconds(500));
    EXPECT_FALSE(b.state().running);
    EXPECT_EQ(b.state().last_run_end, LogiRunEnd::disconnect);
    EXPECT_TRUE(b.state().station_armed);
    EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  }
}

TEST(LogiFirmware, AnAutoRunFinishesWithNoClientConnected) {
  Bench b;
  b.start_run("001");
  b.client().pipe->close();
  b.run_until(at_ms(10000));
  EXPECT_FALSE(b.fw().connected());
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::arrived);
  EXPECT_NEAR(b.pose().x_m, 2.0, 0.05);
}

// ---------------------------------------------------------------- construction

TEST(LogiFirmware, RefusesAVehicleWithoutMecanumWheels) {
  sim::World world({sim::default_warehouse_arena()});
  sim::Vehicle& robot = world.add_vehicle(sim::arduino_robot());
  EXPECT_THROW(LogiFirmware(world, robot), std::invalid_argument);
}

TEST(LogiFirmware, RefusesConfigValuesOutOfRange) {
  sim::World world({sim::default_warehouse_arena()});
  sim::Vehicle& car = world.add_vehicle(sim::logi_car());
  const auto make = [&](auto change) {
    LogiConfig config;
    change(config);
    return LogiFirmware(world, car, config);
  };
  EXPECT_THROW(make([](LogiConfig& c) { c.stations = {1, 1000}; }), std::invalid_argument);
  EXPECT_THROW(make([](LogiConfig& c) { c.boot_speed_percent = 101; }), std::invalid_argument);
  EXPECT_THROW(make([](LogiConfig& c) { c.stat_period = {}; }), std::invalid_argument);
  EXPECT_THROW(make([](LogiConfig& c) { c.control_period = {}; }), std::invalid_argument);
  EXPECT_THROW(make([](LogiConfig& c) { c.obstacle_stop_cm = -1; }), std::invalid_argument);
  EXPECT_NO_THROW(make([](LogiConfig& c) { c.boot_mode = Mode::manual; }));
}

TEST(LogiFirmware, BootSettingsAreConfigurable) {
  LogiConfig config;
  config.boot_speed_percent = 30;
  config.boot_mode = Mode::manual;
  Bench b(config, open_floor());
  EXPECT_EQ(b.state().speed_percent, 30);
  EXPECT_EQ(b.ask("MV:FWD"), "FB:MV:1");
  EXPECT_EQ(b.fw().summary(), "MAN FWD SP 30 DIS 186");
}

}  // namespace
}  // namespace hil::mocks
