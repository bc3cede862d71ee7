// The WR8 mock firmware's tasks under the virtual-time driver: every task
// and its answers, settings and the PID drive, the servo zero, the fault
// state and scripted behaviours, with exact times.

#include "mocks/wr8.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "protocol/wr8/codec.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/wr8_gui.hpp"

namespace hil::mocks::test {
namespace {

using link::milliseconds;

using Gui = Wr8Gui;

// ---------------------------------------------------------------- tasks

TEST(Wr8Task, CheckCompletesAtOnce) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.task(7, wr8::TaskCode::check);
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 7, kCompleted}}));
  gui.send_unchecked(wr8::Task{8, wr8::TaskCode::check, {wr8::Word::from_i32(1)}});
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 8, kError}}));
}

TEST(Wr8Task, DriveCompletesOnTheFirstControlTickAfterTheWheelsCovered100Cm) {
  Gui gui;
  gui.settle(at_ms(1000));
  const sim::Pose start = gui.vehicle().pose();
  gui.drive(1, 100);
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kStarted}}));
  EXPECT_EQ(gui.fw().state_code(), wr8::State::run);
  // Watch every control tick: no answer while the wheels have covered less
  // than 100 cm, completed on the tick they reach it.
  std::optional<std::int64_t> completed_ms;
  for (std::int64_t t = 1010; t <= 8000 && !completed_ms; t += 10) {
    gui.run_until(at_ms(t));
    const double covered_m = gui.vehicle().odometry().distance_m;
    const auto got = answers(gui.take());
    if (covered_m < 1.0) {
      EXPECT_TRUE(got.empty()) << t;
    } else {
      EXPECT_EQ(got, (std::vector<Answer>{{t, 1, kCompleted}}));
      completed_ms = t;
    }
  }
  ASSERT_TRUE(completed_ms.has_value());
  // Consistent with the speed: at best 0.5 s to reach 0.5 m/s at 1 m/s^2
  // (12.5 cm), then 87.5 cm at 0.5 m/s, 2.25 s in all; the controller slows
  // down for the last 33 cm, so it takes longer, but not twice as long.
  const std::int64_t took_ms = *completed_ms - 1000;
  EXPECT_GE(took_ms, 2250);
  EXPECT_LE(took_ms, 4500);
  EXPECT_EQ(gui.fw().state_code(), wr8::State::stop);
  // The car stops cleanly: less than 1 cm past the distance, straight ahead.
  gui.run_until(at_ms(*completed_ms + 500));
  EXPECT_EQ(gui.chassis().speed_mps(), 0.0);
  EXPECT_GE(gui.vehicle().odometry().distance_m, 1.0);
  EXPECT_LT(gui.vehicle().odometry().distance_m, 1.01);
  const sim::Pose end = gui.vehicle().pose();
  EXPECT_NEAR(end.x_m - start.x_m, 1.0, 0.01);
  EXPECT_NEAR(end.y_m, start.y_m, 0.001);
  EXPECT_EQ(gui.state().tasks_completed, 1u);
}

TEST(Wr8Task, DriveRefusesDistancesItCannotDrive) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.drive(1, 0);
  gui.drive(2, -10);
  gui.drive(3, 1001);  // past max_drive_cm
  gui.send_unchecked(
      wr8::Task{4, wr8::TaskCode::drive, {wr8::Word::from_i32(10), wr8::Word::from_i32(10)}});
  EXPECT_EQ(answers(gui.take()),
            (std::vector<Answer>{
                {1000, 1, kError}, {1000, 2, kError}, {1000, 3, kError}, {1000, 4, kError}}));
  gui.run_until(at_ms(1500));
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  EXPECT_EQ(gui.state().tasks_failed, 4u);
}

TEST(Wr8Task, ANewMotionTaskWhileOneRunsIsAnErrorAndTheRunningOneGoesOn) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.drive(1, 50);
  gui.run_until(at_ms(1200));
  gui.drive(2, 50);
  gui.turn(3, 10);
  gui.task(4, wr8::TaskCode::check);  // not a motion task
  gui.task(5, wr8::TaskCode::blink);  // nor this
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kStarted},
                                                      {1200, 2, kError},
                                                      {1200, 3, kError},
                                                      {1200, 4, kCompleted},
                                                      {1200, 5, kStarted}}));
  gui.run_until(at_ms(5000));
  auto done = answers(gui.take());
  std::sort(done.begin(), done.end(),
            [](const Answer& a, const Answer& b) { return a.coi < b.coi; });
  ASSERT_EQ(done.size(), 2u);
  EXPECT_EQ(done[0].coi, 1);
  EXPECT_EQ(done[0].code, kCompleted);
  EXPECT_EQ(done[1], (Answer{3200, 5, kCompleted}));
  EXPECT_NEAR(gui.vehicle().odometry().distance_m, 0.50, 0.01);
  EXPECT_EQ(gui.chassis().steering_rad(), 0.0);  // the refused turn did nothing
}

TEST(Wr8Task, TurnCompletesWhenTheWheelsReachTheAngle) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.turn(1, 15);
  // The servo slews 1.5 degrees per 1/120 s step: ten steps, the last ending
  // at 1083.3 ms; the control tick at 1090 ms sees the wheels there.
  gui.run_until(at_ms(1089));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kStarted}}));
  gui.run_until(at_ms(1100));
  const auto got = gui.take();
  EXPECT_EQ(answers(got), (std::vector<Answer>{{1090, 1, kCompleted}}));
  const auto data = select<wr8::Data>(got);
  ASSERT_EQ(data.size(), 1u);
  EXPECT_EQ(data[0].second.state, wr8::State::stop);
  EXPECT_FLOAT_EQ(static_cast<float>(value(data[0].second, wr8::data_code::wheel_angle)), 15.0f);
  EXPECT_EQ(gui.state().commanded_wheel_angle_deg, 15.0);
  // Back to -15: 30 degrees, twenty steps from 1100 ms, the last ending at 1266.7 ms.
  gui.turn(2, -15);
  gui.run_until(at_ms(1300));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1100, 2, kStarted}, {1270, 2, kCompleted}}));
  EXPECT_NEAR(gui.chassis().steering_rad(), sim::deg_to_rad(-15), 1e-12);
}

TEST(Wr8Task, RunStateWhileTheWheelsTurn) {
  Gui gui;
  gui.authenticate();
  gui.run_until(at_ms(1050));
  gui.turn(1, 30);  // 20 steps, 166.7 ms
  gui.run_until(at_ms(1100));
  const auto data = select<wr8::Data>(gui.take());
  ASSERT_FALSE(data.empty());
  EXPECT_EQ(data.back().second.state, wr8::State::run);
  const double angle = value(data.back().second, wr8::data_code::wheel_angle);
  EXPECT_GT(angle, 0);
  EXPECT_LT(angle, 30);
}

TEST(Wr8Task, TurnOutOfTheSteeringRangeIsAnError) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.turn(1, 31);
  gui.turn(2, -31);
  gui.turn(3, 30);  // the limit itself is fine
  gui.run_until(at_ms(1500));
  EXPECT_EQ(answers(gui.take()),
            (std::vector<Answer>{
                {1000, 1, kError}, {1000, 2, kError}, {1000, 3, kStarted}, {1170, 3, kCompleted}}));
}

TEST(Wr8Task, TurningToTheAngleTheWheelsAlreadyHaveCompletesOnTheNextTick) {
  Gui gui;
  gui.settle(at_ms(1003));
  gui.turn(1, 0);
  gui.run_until(at_ms(1100));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1003, 1, kStarted}, {1010, 1, kCompleted}}));
}

TEST(Wr8Task, BlinkCompletesAfterTheBlinkTimeInWaitState) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.task(1, wr8::TaskCode::blink);
  gui.run_until(at_ms(1500));
  gui.task(2, wr8::TaskCode::blink);  // one blink at a time
  gui.run_until(at_ms(3100));
  const auto got = gui.take();
  EXPECT_EQ(answers(got),
            (std::vector<Answer>{{1000, 1, kStarted}, {1500, 2, kError}, {3000, 1, kCompleted}}));
  for (const auto& [t, d] : select<wr8::Data>(got))
    EXPECT_EQ(d.state, ms_of(t) < 3000 ? wr8::State::wait : wr8::State::stop) << ms_of(t);
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
}

TEST(Wr8Task, BlinkTimeIsConfigurable) {
  Wr8Config config;
  config.blink_duration = milliseconds(750);
  Gui gui(config);
  gui.settle(at_ms(1000));
  gui.task(1, wr8::TaskCode::blink);
  gui.run_until(at_ms(2000));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kStarted}, {1750, 1, kCompleted}}));
}

TEST(Wr8Task, GetSettingsSendsAllFourSettingsWithTheSameCoiThenCompleted) {
  Gui gui;
  gui.authenticate_raw();
  gui.client().write(wr8::encode(wr8::Task{5, wr8::TaskCode::get_settings, {}}));
  gui.car().run_for(milliseconds(0));
  // SETTINGS COI 5: P 1.5, I 0.25, D 0.05 (float32), servo zero 90 (int32); then RESPONSE.
  EXPECT_EQ(gui.take_hex(),
            "04 05 14 00 00 00 C0 3F 01 00 00 80 3E 02 CD CC 4C 3D 03 5A 00 00 00 05 05 02");
}

// ---------------------------------------------------------------- settings

TEST(Wr8Settings, RoundTripThroughGetSettings) {
  Gui gui;
  gui.authenticate();
  gui.take();
  const std::vector<wr8::Setting> wanted = {setting(wr8::SettingCode::p, 3.0f),
                                            setting(wr8::SettingCode::i, 0.5f),
                                            setting(wr8::SettingCode::d, 0.125f), servo_zero(92)};
  gui.settings(1, wanted);
  gui.task(2, wr8::TaskCode::get_settings);
  const auto got = gui.take();
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(std::get<wr8::Response>(got[0].message), (wr8::Response{1, kCompleted}));
  EXPECT_EQ(std::get<wr8::Settings>(got[1].message), (wr8::Settings{2, wanted}));
  EXPECT_EQ(std::get<wr8::Response>(got[2].message), (wr8::Response{2, kCompleted}));
  EXPECT_EQ(gui.state().p, 3.0);
  EXPECT_EQ(gui.state().servo_zero_deg, 92.0);
}

TEST(Wr8Settings, EntriesApplyInOrderAndAnEmptySettingsIsFine) {
  Gui gui;
  gui.authenticate();
  gui.take();
  gui.settings(1, {setting(wr8::SettingCode::p, 2.0f), setting(wr8::SettingCode::p, 2.5f)});
  gui.settings(2, {});
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1, 1, kCompleted}, {1, 2, kCompleted}}));
  EXPECT_EQ(gui.state().p, 2.5);
}

TEST(Wr8Settings, AnInvalidValueIsAnErrorAndChangesNothing) {
  Gui gui;
  gui.authenticate();
  gui.take();
  gui.settings(1, {setting(wr8::SettingCode::p, -1.0f)});
  gui.settings(2, {setting(wr8::SettingCode::i, std::nanf(""))});
  gui.settings(3, {setting(wr8::SettingCode::d, std::numeric_limits<float>::infinity())});
  gui.settings(4, {setting(wr8::SettingCode::p, 101.0f)});  // above max_gain
  gui.settings(5, {servo_zero(181)});
  gui.settings(6, {servo_zero(-1)});
  // One bad entry spoils the whole packet: P stays as it was.
  gui.settings(7, {setting(wr8::SettingCode::p, 4.0f), servo_zero(500)});
  const auto got = answers(gui.take());
  ASSERT_EQ(got.size(), 7u);
  for (const auto& a : got)
    EXPECT_EQ(a.code, kError) << a;
  gui.task(8, wr8::TaskCode::get_settings);
  const auto settings = select<wr8::Settings>(gui.take());
  ASSERT_EQ(settings.size(), 1u);
  EXPECT_EQ(settings[0].second.params,
            (std::vector<wr8::Setting>{setting(wr8::SettingCode::p, 1.5f),
                                       setting(wr8::SettingCode::i, 0.25f),
                                       setting(wr8::SettingCode::d, 0.05f), servo_zero(90)}));
}

TEST(Wr8Settings, ZeroGainsMeanNoMotionAndTheDriveFailsAfterTheStallTimeout) {
  Gui gui;
  gui.authenticate();
  gui.run_until(at_ms(1000));
  gui.settings(1, {setting(wr8::SettingCode::p, 0), setting(wr8::SettingCode::i, 0),
                   setting(wr8::SettingCode::d, 0)});
  gui.take();
  gui.drive(2, 100);
  gui.run_until(at_ms(2999));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 2, kStarted}}));
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  gui.run_until(at_ms(3100));
  const auto got = gui.take();
  EXPECT_EQ(answers(got), (std::vector<Answer>{{3000, 2, kError}}));
  EXPECT_EQ(select<wr8::Data>(got).back().second.state, wr8::State::stop);
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  EXPECT_FALSE(gui.state().drive.has_value());
}

TEST(Wr8Settings, TheStallTimeoutIsConfigurable) {
  Wr8Config config;
  config.p = config.i = config.d = 0;
  config.stall_timeout = milliseconds(500);
  Gui gui(config);
  gui.settle(at_ms(1000));
  gui.drive(1, 100);
  gui.run_until(at_ms(2000));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kStarted}, {1500, 1, kError}}));
}

/// How long a 100 cm drive takes with these gains, in ms (0: never done).
std::int64_t drive_100_ms(float p, float i, float d) {
  Gui gui;
  gui.authenticate();
  gui.run_until(at_ms(1000));
  gui.settings(1, {setting(wr8::SettingCode::p, p), setting(wr8::SettingCode::i, i),
                   setting(wr8::SettingCode::d, d)});
  gui.take();
  gui.drive(2, 100);
  gui.run_until(at_ms(20000));
  for (const Answer& a : answers(gui.take())) {
    if (a.code == kCompleted) {
      EXPECT_GE(gui.vehicle().odometry().distance_m, 1.0);
      return a.at_ms - 1000;
    }
  }
  return 0;
}

TEST(Wr8Settings, TheGainsChangeHowTheCarDrives) {
  const std::int64_t standard = drive_100_ms(1.5f, 0.25f, 0.05f);
  const std::int64_t soft = drive_100_ms(0.5f, 0, 0);
  const std::int64_t integral_only = drive_100_ms(0, 0.5f, 0);
  ASSERT_GT(standard, 0);
  // A smaller P slows down sooner and crawls longer.
  EXPECT_GT(soft, standard + 1000);
  // I alone still gets there, its integral building up the speed.
  EXPECT_GT(integral_only, 0);
  EXPECT_NE(integral_only, standard);
}

TEST(Wr8Settings, ServoZeroOffsetsTheWheelsAndTheCarDrifts) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.settings(1, {servo_zero(95)});  // 5 servo degrees left of the mechanical centre
  gui.run_until(at_ms(1100));
  auto got = gui.take();
  EXPECT_EQ(answers(got), (std::vector<Answer>{{1000, 1, kCompleted}}));
  // Straight ahead is still what was commanded, but the wheel angle shows 5 degrees.
  EXPECT_EQ(gui.state().commanded_wheel_angle_deg, 0.0);
  EXPECT_FLOAT_EQ(
      static_cast<float>(value(select<wr8::Data>(got).back().second, wr8::data_code::wheel_angle)),
      5.0f);
  const sim::Pose start = gui.vehicle().pose();
  gui.drive(2, 100);
  gui.run_until(at_ms(6000));
  got = gui.take();
  ASSERT_EQ(answers(got).back().code, kCompleted);
  // 1 m on a 2.97 m radius (wheelbase 0.26 m / tan 5 deg): 19.3 degrees and
  // 16.7 cm to the left.
  const sim::Pose end = gui.vehicle().pose();
  EXPECT_NEAR(sim::rad_to_deg(end.heading_rad - start.heading_rad), 19.3, 0.5);
  EXPECT_NEAR(end.y_m - start.y_m, 0.167, 0.01);

  // Below the centre the wheels point right.
  Gui right;
  right.authenticate();
  right.settings(1, {servo_zero(84)});
  right.run_until(at_ms(200));
  EXPECT_NEAR(sim::rad_to_deg(right.chassis().steering_rad()), -6.0, 1e-9);
  // A turn task adds to the offset.
  right.turn(2, 10);
  right.run_until(at_ms(300));
  EXPECT_NEAR(sim::rad_to_deg(right.chassis().steering_rad()), 4.0, 1e-9);
}

TEST(Wr8Settings, TheMechanicalCentreIsConfigurable) {
  Wr8Config config;
  config.servo_center_deg = 93;  // this car's servo horn sits three degrees off
  Gui gui(config);
  gui.authenticate();
  gui.run_until(at_ms(200));
  EXPECT_NEAR(sim::rad_to_deg(gui.chassis().steering_rad()), -3.0, 1e-9);
  gui.settings(1, {servo_zero(93)});  // calibrated
  gui.run_until(at_ms(300));
  EXPECT_NEAR(gui.chassis().steering_rad(), 0.0, 1e-12);
}

// ---------------------------------------------------------------- faults and behaviours

TEST(Wr8Fault, StopsTheCarFailsTheTaskAndRefusesTasksUntilCleared) {
  Gui gui;
  gui.authenticate();
  gui.run_until(at_ms(1000));
  gui.drive(1, 100);
  gui.fw().arm(Behaviour{"", When{at_ms(2000), "", 1}, EnterFault{}});
  gui.fw().arm(Behaviour{"", When{at_ms(3000), "", 1}, ClearFault{}});
  gui.run_until(at_ms(2500));
  gui.task(2, wr8::TaskCode::check);
  gui.drive(3, 10);
  gui.settings(4, {setting(wr8::SettingCode::p, 2.0f)});  // settings still apply
  gui.send(wr8::Auth{gui.config().profile.auth_text});
  auto got = gui.take();
  EXPECT_EQ(answers(got), (std::vector<Answer>{{1000, 1, kStarted},
                                               {2000, 1, kError},
                                               {2500, 2, kError},
                                               {2500, 3, kError},
                                               {2500, 4, kCompleted}}));
  EXPECT_EQ(select<wr8::AuthReply>(got).back().second.state, wr8::State::fault);
  for (const auto& [t, d] : select<wr8::Data>(got))
    EXPECT_EQ(d.state, ms_of(t) <= 1000  ? wr8::State::stop
                       : ms_of(t) < 2000 ? wr8::State::run
                                         : wr8::State::fault)
        << ms_of(t);
  // Braking from at most 0.5 m/s at 2 m/s^2 takes 0.25 s.
  EXPECT_EQ(gui.chassis().speed_mps(), 0.0);
  const double stopped_at = gui.vehicle().odometry().distance_m;
  EXPECT_LT(stopped_at, 1.0);
  gui.run_until(at_ms(3100));
  EXPECT_EQ(gui.vehicle().odometry().distance_m, stopped_at);
  got = gui.take();
  EXPECT_EQ(select<wr8::Data>(got).back().second.state, wr8::State::stop);
  gui.task(5, wr8::TaskCode::check);
  gui.drive(6, 10);
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{3100, 5, kCompleted}, {3100, 6, kStarted}}));
}

TEST(Wr8Behaviour, RejectAnswersErrorWithNoEffect) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.fw().arm(Behaviour{"", When{}, Reject{"TASK", 1}});
  gui.fw().arm(Behaviour{"", When{}, Reject{"SETTINGS", 1}});
  gui.drive(1, 100);
  gui.settings(2, {servo_zero(100)});
  gui.run_until(at_ms(1500));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kError}, {1000, 2, kError}}));
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  EXPECT_EQ(gui.state().servo_zero_deg, 90.0);
  EXPECT_EQ(gui.fw().stats().rejected, 2u);
  gui.drive(3, 10);  // the reject is used up
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1500, 3, kStarted}}));
}

TEST(Wr8Behaviour, ARejectedAuthIsARefusedLogin) {
  Gui gui;
  gui.fw().arm(Behaviour{"", When{}, Reject{"AUTH", 1}});
  gui.send(wr8::Auth{gui.config().profile.auth_text});
  EXPECT_EQ(gui.state().session, Wr8Session::refused);
  gui.run_until(at_ms(1001));
  EXPECT_TRUE(gui.take().empty());
  EXPECT_TRUE(gui.client().closed.has_value());
}

TEST(Wr8Behaviour, IgnoreSwallowsCommandsWithoutAnswerOrEffect) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.fw().arm(Behaviour{"", When{}, Ignore{"TASK", 2, std::nullopt}});
  gui.drive(1, 100);
  gui.task(2, wr8::TaskCode::check);
  gui.run_until(at_ms(1500));
  const auto got = gui.take();
  EXPECT_TRUE(answers(got).empty());
  EXPECT_EQ(select<wr8::Data>(got).size(), 5u);  // DATA goes on
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  EXPECT_EQ(gui.fw().stats().ignored, 2u);
  gui.task(3, wr8::TaskCode::check);
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1500, 3, kCompleted}}));
}

TEST(Wr8Behaviour, AfterFrameTriggersCountHandledTasks) {
  Gui gui;
  gui.authenticate();
  gui.take();
  gui.fw().arm(Behaviour{"", When{std::nullopt, "TASK", 2}, SendBytes{{0x05, 0x63, 0x00}}});
  gui.task(1, wr8::TaskCode::check);
  gui.task(2, wr8::TaskCode::check);
  EXPECT_EQ(answers(gui.take()),
            (std::vector<Answer>{{1, 1, kCompleted}, {1, 2, kCompleted}, {1, 0x63, kError}}));
}

}  // namespace
}  // namespace hil::mocks::test
