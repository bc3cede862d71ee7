// The LOGI car's mock firmware moving in the world under the virtual-time
// driver: manual mecanum motion, the line-following auto mode and the
// obstacle lock.

#include "mocks/logi.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sim/presets.hpp"
#include "tests/mocks/logi_bench.hpp"

namespace hil::mocks::test {
namespace {

using link::milliseconds;
using link::seconds;
using link::Time;
using logi::Direction;

constexpr double kTolM = 0.005;

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
    ManualLogiBench b;
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
  ManualLogiBench b;
  b.ask("MV:LF");
  b.run_for(seconds(1));
  const sim::Twist v = b.vehicle().velocity();
  EXPECT_NEAR(v.vx_mps, v.vy_mps, 1e-4);
  EXPECT_NEAR(speed_of(v), 0.25 / std::sqrt(2.0), 1e-3);
}

TEST(LogiFirmware, MoveStopAndANewMoveTakeOverAtOnce) {
  ManualLogiBench b;
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
  ManualLogiBench b;
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
    ManualLogiBench b;
    b.ask("SP:" + std::string(sp < 100 ? "0" : "") + std::to_string(sp));
    b.ask("MV:CW");
    b.run_for(seconds(1));
    // wz = r * w / (lx + ly) with w = 12.5 rad/s * SP / 100: 159 degrees/s at 100 %.
    EXPECT_NEAR(b.vehicle().velocity().wz_radps, -0.04 * 12.5 * sp / 100 / 0.18, 1e-3) << sp;
  }
}

TEST(LogiFirmware, StopCommandAndModeSwitchHaltManualMotion) {
  ManualLogiBench b;
  struct Halt {
    const char* move;
    const char* command;
    const char* answer;
  };
  for (const Halt& h :
       {Halt{"MV:RIGHT", "ST:STOP", "FB:ST:1"}, Halt{"MV:FWD", "MD:AUTO", "FB:MD:1"}}) {
    SCOPED_TRACE(h.command);
    b.ask(h.move);
    b.run_for(milliseconds(500));
    EXPECT_EQ(b.ask(h.command), h.answer);
    EXPECT_EQ(b.state().manual, Direction::stop);
    b.run_for(milliseconds(500));
    EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  }
}

// ---------------------------------------------------------------- auto mode

TEST(LogiFirmware, AutoRunFromTheStartStopsOnStation001AndNeedsGsAgain) {
  LogiBench b;
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
  LogiBench b;
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
    LogiBench b;
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
  LogiBench b;
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
  LogiBench b;
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
  LogiBench b;
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
  LogiBench b;
  b.start_run("002");
  b.run_for(milliseconds(500));
  EXPECT_EQ(b.ask("GS:001"), "FB:GS:0");
  EXPECT_EQ(b.state().station, 2);
  EXPECT_TRUE(b.state().running);
}

TEST(LogiFirmware, ManualModeTakesOverFromARun) {
  LogiBench b;
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
  LogiBench b({}, short_tape());
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
  LogiBench b({}, corridor());
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
  LogiBench b({}, corridor());
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
    LogiBench b(config, corridor());
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
  LogiBench b(config, corridor());
  b.ask("MD:MAN");
  b.ask("MV:FWD");
  ASSERT_TRUE(b.run_until([&] { return b.state().obstacle; }, seconds(10)));
  EXPECT_LT(b.state().distance_cm, 50);
  EXPECT_GE(b.state().distance_cm, 45);
}

}  // namespace
}  // namespace hil::mocks::test
