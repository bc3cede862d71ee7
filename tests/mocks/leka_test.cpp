// The mock Leka Alpha firmware's commands under the virtual-time driver:
// construction, the info answer and the main loop's timing, every LED and
// motor command's effect, motion in the world, behaviours, the fault state,
// scripted rejects and ignores, and what happens when the client leaves.
// Bad input, the serial buffer and the properties: leka_input_test.cpp.

#include "mocks/leka.hpp"

#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <variant>

#include "sim/presets.hpp"
#include "tests/mocks/leka_test_support.hpp"

namespace hil::mocks::test {
namespace {

// ------------------------------------------------------------ construction

TEST(LekaFirmwareSetup, RefusesAVehicleWithoutADifferentialChassis) {
  sim::World world(sim::WorldDef{});
  auto& vehicle = world.add_vehicle(sim::logi_car());
  EXPECT_THROW(LekaFirmware(world, vehicle), std::invalid_argument);
}

TEST(LekaFirmwareSetup, RefusesConfigValuesOutOfRange) {
  sim::World world(sim::WorldDef{});
  auto& vehicle = world.add_vehicle(sim::leka_robot());
  const auto refuses = [&](auto change) {
    LekaConfig c;
    change(c);
    EXPECT_THROW(LekaFirmware(world, vehicle, c), std::invalid_argument);
  };
  refuses([](LekaConfig& c) { c.loop_period = milliseconds(0); });
  refuses([](LekaConfig& c) { c.serial_buffer_bytes = 6; });
  refuses([](LekaConfig& c) { c.serial_buffer_bytes = 262; });
  refuses([](LekaConfig& c) { c.robot_name = "two words"; });
  refuses([](LekaConfig& c) { c.firmware_version = ""; });
  refuses([](LekaConfig& c) { c.motivator_duration = milliseconds(0); });
  refuses([](LekaConfig& c) { c.guidance_blink = milliseconds(-1); });
  EXPECT_NO_THROW(LekaFirmware(world, vehicle, LekaConfig{}));
}

TEST_F(LekaTest, StartsDarkAndStillWithTwentyBeltLeds) {
  EXPECT_EQ(car.firmware().protocol(), "leka");
  EXPECT_EQ(state().belt.size(), 20u);
  EXPECT_EQ(state().ears[0], kOff);
  EXPECT_EQ(state().left, LekaMotor{});
  EXPECT_FALSE(state().behaviour.has_value());
  EXPECT_EQ(car.firmware().summary(), "L+0 R+0 EARS 000000 000000 BELT 0/20");
  // Nothing to read, play or drive: the firmware asks for no wakeup.
  EXPECT_FALSE(car.firmware().next_wakeup().has_value());
}

// ------------------------------------------------------------ info and timing

TEST_F(LekaTest, InfoIsAnsweredAtTheNextLoopPassWithTheDocumentedLine) {
  client->write(kSeedInfo);
  car.run_until(at_ms(9));
  EXPECT_EQ(client->text(), "");
  EXPECT_EQ(state().serial_buffered, 7u);
  car.run_until(at_ms(10));
  EXPECT_EQ(client->take_text(), kInfoLine);
  EXPECT_EQ(state().serial_buffered, 0u);
  EXPECT_EQ(state().counters.info_answers, 1u);
  EXPECT_EQ(car.firmware().stats().frames_in, 1u);
  EXPECT_EQ(car.firmware().stats().frames_out, 1u);
}

TEST(LekaFirmwareTiming, PassesFollowTheConfiguredLoopPeriod) {
  LekaConfig config;
  config.loop_period = milliseconds(25);
  config.robot_name = "alpha-7";
  config.firmware_version = "2.3";
  auto car = make_car(config);
  auto client = car.connect();
  client->write(kSeedInfo);
  car.run_until(at_ms(24));
  EXPECT_EQ(client->text(), "");
  car.run_until(at_ms(25));
  EXPECT_EQ(client->take_text(), "LEKA name=alpha-7 firmware=2.3 buffer=128 state=ok\r\n");
}

TEST_F(LekaTest, AFrameSplitAcrossPassesWaitsInTheBufferUntilWhole) {
  client->write(Bytes(kSeedInfo.begin(), kSeedInfo.begin() + 3));
  car.run_until(at_ms(10));
  EXPECT_EQ(state().serial_buffered, 3u);
  car.run_until(at_ms(15));
  client->write(Bytes(kSeedInfo.begin() + 3, kSeedInfo.end()));
  car.run_until(at_ms(19));
  EXPECT_EQ(client->text(), "");
  car.run_until(at_ms(20));
  EXPECT_EQ(client->take_text(), kInfoLine);
}

// ------------------------------------------------------------ LEDs

TEST_F(LekaTest, SeedFrameTurnsBeltLedZeroRed) {
  send_and_pass(kSeedBeltRed);
  EXPECT_EQ(state().belt[0], kRed);
  EXPECT_EQ(state().belt[1], kOff);
  EXPECT_EQ(state().ears[0], kOff);
  EXPECT_EQ(state().counters.commands_run, 1u);
  EXPECT_EQ(client->text(), "");  // the robot answers nothing but info
}

TEST_F(LekaTest, SeedTwentyLedFrameSetsEveryBeltLedInOnePass) {
  send_and_pass(kSeedBelt20);
  EXPECT_EQ(state().belt[0], (Rgb{0x33, 0, 0}));
  EXPECT_EQ(state().belt[4], (Rgb{0xFF, 0, 0}));
  EXPECT_EQ(state().belt[5], kOff);
  EXPECT_EQ(state().belt[9], (Rgb{0, 0xCC, 0}));
  EXPECT_EQ(state().belt[15], (Rgb{0, 0, 0xCC}));
  EXPECT_EQ(state().belt[18], kBlue);
  EXPECT_EQ(state().belt[19], kWhite);
  EXPECT_EQ(state().counters.commands_run, 20u);
  EXPECT_EQ(car.firmware().stats().frames_in, 1u);
}

TEST_F(LekaTest, EarCommandsSetBothOrOneEar) {
  send_and_pass(frame({leka::EarAll{kGreen}}));
  EXPECT_EQ(state().ears[0], kGreen);
  EXPECT_EQ(state().ears[1], kGreen);
  send_and_pass(frame({leka::EarSingle{1, kBlue}}));
  EXPECT_EQ(state().ears[0], kGreen);
  EXPECT_EQ(state().ears[1], kBlue);
}

TEST_F(LekaTest, BeltCommandsSetAllARangeOrOneLed) {
  send_and_pass(frame({leka::BeltAll{kBlue}}));
  for (const auto& led : state().belt)
    EXPECT_EQ(led, kBlue);
  send_and_pass(frame({leka::BeltRange{3, 5, kGreen}}));
  EXPECT_EQ(state().belt[2], kBlue);
  EXPECT_EQ(state().belt[3], kGreen);
  EXPECT_EQ(state().belt[5], kGreen);
  EXPECT_EQ(state().belt[6], kBlue);
  send_and_pass(frame({leka::BeltSingle{19, kRed}}));
  EXPECT_EQ(state().belt[19], kRed);
  EXPECT_EQ(state().belt[18], kBlue);
  EXPECT_EQ(car.firmware().summary(), "L+0 R+0 EARS 000000 000000 BELT 20/20");
}

TEST_F(LekaTest, StopLedTurnsEveryLedOffAndLeavesTheMotors) {
  send_and_pass(frame({leka::EarAll{kRed}, leka::BeltAll{kRed}, leka::MotorAll{0, 100}}));
  send_and_pass(frame({leka::StopLed{}}));
  EXPECT_EQ(state().ears[0], kOff);
  EXPECT_EQ(state().ears[1], kOff);
  for (const auto& led : state().belt)
    EXPECT_EQ(led, kOff);
  EXPECT_EQ(state().left, (LekaMotor{0, 100}));
  EXPECT_EQ(chassis().left_pwm(), 100);
}

// ------------------------------------------------------------ motors

TEST_F(LekaTest, MotorCommandsSetSpinAndSpeedPerSideAndTheChassisDuty) {
  send_and_pass(frame({leka::MotorAll{leka::kSpinBackward, 200}}));
  EXPECT_EQ(state().left, (LekaMotor{1, 200}));
  EXPECT_EQ(state().right, (LekaMotor{1, 200}));
  EXPECT_EQ(chassis().left_pwm(), -200);
  EXPECT_EQ(chassis().right_pwm(), -200);

  send_and_pass(frame({leka::MotorDuo{0, 10, 1, 20}}));
  EXPECT_EQ(state().left, (LekaMotor{0, 10}));
  EXPECT_EQ(state().right, (LekaMotor{1, 20}));
  EXPECT_EQ(chassis().left_pwm(), 10);
  EXPECT_EQ(chassis().right_pwm(), -20);

  send_and_pass(frame({leka::MotorLeft{1, 255}}));
  EXPECT_EQ(chassis().left_pwm(), -255);
  EXPECT_EQ(chassis().right_pwm(), -20);  // the right motor keeps its command

  send_and_pass(frame({leka::MotorRight{0, 77}}));
  EXPECT_EQ(chassis().left_pwm(), -255);
  EXPECT_EQ(chassis().right_pwm(), 77);
  EXPECT_EQ(car.firmware().summary(), "L-255 R+77 EARS 000000 000000 BELT 0/20");
}

TEST(LekaFirmwareMotors, SpeedByteIsScaledToTheChassisPwmRange) {
  sim::VehicleDef def = sim::leka_robot();
  auto chassis_def = std::get<sim::DifferentialDef>(def.chassis);
  chassis_def.max_pwm = 100;
  def.chassis = chassis_def;
  auto car = make_car({}, def);
  const auto& fw = car.firmware();
  EXPECT_EQ(fw.pwm_of({0, 255}), 100);
  EXPECT_EQ(fw.pwm_of({0, 128}), 50);  // 50.2 rounds to 50
  EXPECT_EQ(fw.pwm_of({1, 128}), -50);
  EXPECT_EQ(fw.pwm_of({1, 0}), 0);
  auto client = car.connect();
  client->write(frame({leka::MotorAll{0, 255}}));
  car.run_until(at_ms(10));
  EXPECT_EQ(car.vehicle().differential()->left_pwm(), 100);
}

TEST_F(LekaTest, MultiCommandFrameRunsLedsAndMotorsInOnePass) {
  // The profile's example: led.ear.all 255 0 0 + motor.all 1 200.
  const Bytes bytes = hex("2A 2B 2C 2D 07 11 FF 00 00 21 01 C8 D8");
  ASSERT_EQ(bytes, frame({leka::EarAll{kRed}, leka::MotorAll{1, 200}}));
  client->write(bytes);
  car.run_until(at_ms(9));
  EXPECT_EQ(state().ears[0], kOff);
  EXPECT_EQ(chassis().left_pwm(), 0);
  car.run_until(at_ms(10));
  EXPECT_EQ(state().ears[0], kRed);
  EXPECT_EQ(state().ears[1], kRed);
  EXPECT_EQ(chassis().left_pwm(), -200);
  EXPECT_EQ(chassis().right_pwm(), -200);
  EXPECT_EQ(state().counters.commands_run, 2u);
  EXPECT_EQ(car.firmware().stats().frames_in, 1u);
}

TEST_F(LekaTest, CommandsOfAGroupRunInOrder) {
  // The later command wins where two touch the same LED or motor.
  send_and_pass(frame({leka::BeltAll{kRed}, leka::BeltSingle{2, kGreen}, leka::MotorAll{0, 50},
                       leka::MotorRight{1, 60}, leka::EarSingle{0, kBlue}, leka::EarAll{kGreen}}));
  EXPECT_EQ(state().belt[1], kRed);
  EXPECT_EQ(state().belt[2], kGreen);
  EXPECT_EQ(state().left, (LekaMotor{0, 50}));
  EXPECT_EQ(state().right, (LekaMotor{1, 60}));
  EXPECT_EQ(state().ears[0], kGreen);
}

TEST_F(LekaTest, DrivingForwardMovesTheRobotInTheWorld) {
  const sim::Pose start = car.vehicle().pose();
  client->write(frame({leka::MotorAll{0, 255}}));
  car.run_until(at_ms(10));
  EXPECT_EQ(car.vehicle().pose(), start);  // the motors start with this pass
  car.run_until(at_ms(1010));
  // 0.4 m/s at 255, reached after 0.4 s at 1 m/s^2: 0.08 m + 0.6 s * 0.4 m/s.
  const sim::Pose end = car.vehicle().pose();
  EXPECT_NEAR(end.x_m - start.x_m, 0.32, 0.01);
  EXPECT_NEAR(end.y_m, start.y_m, 0.002);
  EXPECT_NEAR(end.heading_rad, start.heading_rad, 0.01);
  // The firmware keeps the world running while the robot moves.
  EXPECT_EQ(car.firmware().next_wakeup(), at_ms(1020));
}

TEST_F(LekaTest, OppositeSpinsTurnTheRobotOnTheSpot) {
  const sim::Pose start = car.vehicle().pose();
  send_and_pass(frame({leka::MotorDuo{1, 100, 0, 100}}));
  car.run_until(at_ms(1010));
  const sim::Pose end = car.vehicle().pose();
  // Each side 100 * 0.4 / 255 m/s; turn rate 2 v / 0.17 m, after a 0.157 s ramp.
  const double v = 100 * 0.4 / 255;
  const double expected = 2 * v / 0.17 * (1.0 - v / 1.0 / 2);
  EXPECT_NEAR(end.heading_rad - start.heading_rad, expected, 0.03);
  EXPECT_NEAR(end.x_m, start.x_m, 0.01);
  EXPECT_NEAR(end.y_m, start.y_m, 0.01);
}

TEST_F(LekaTest, StopMotorStopsTheRobotAndKeepsTheLeds) {
  send_and_pass(frame({leka::EarAll{kGreen}, leka::MotorAll{0, 255}}));
  car.run_until(at_ms(500));
  send_and_pass(frame({leka::StopMotor{}}));
  EXPECT_EQ(state().left, LekaMotor{});
  EXPECT_EQ(state().right, LekaMotor{});
  EXPECT_EQ(chassis().left_pwm(), 0);
  EXPECT_EQ(state().ears[0], kGreen);
  // It brakes at 1 m/s^2 from 0.4 m/s, then stands still, and the firmware
  // stops asking for wakeups once the wheels are at rest.
  car.run_until(at_ms(1000));
  EXPECT_EQ(chassis().left_speed_mps(), 0.0);
  const sim::Pose rest = car.vehicle().pose();
  EXPECT_FALSE(car.firmware().next_wakeup().has_value());
  car.run_until(at_ms(2000));
  client->write(kSeedInfo);  // any event lets the world catch up
  car.run_for(milliseconds(10));
  EXPECT_EQ(car.vehicle().pose(), rest);
}

TEST_F(LekaTest, StopRobotTurnsOffLedsAndMotors) {
  send_and_pass(frame({leka::EarAll{kGreen}, leka::BeltAll{kBlue}, leka::MotorAll{0, 255}}));
  send_and_pass(frame({leka::StopRobot{}}));
  EXPECT_EQ(state().ears[1], kOff);
  EXPECT_EQ(state().belt[7], kOff);
  EXPECT_EQ(state().left, LekaMotor{});
  EXPECT_EQ(chassis().right_pwm(), 0);
}

// ------------------------------------------------------------ behaviours

TEST_F(LekaTest, MotivatorPlaysItsLightAndTurnThenRestoresTheLeds) {
  send_and_pass(frame({leka::EarAll{kBlue}, leka::BeltSingle{7, kRed}}));
  const sim::Pose start = car.vehicle().pose();
  const double heading0 = start.heading_rad;
  client->write(hex("2A 2B 2C 2D 02 50 52 7A"));  // motivator 0x52 (green)
  car.run_until(at_ms(20));
  ASSERT_TRUE(state().behaviour.has_value());
  EXPECT_EQ(*state().behaviour,
            (LekaBehaviour{LekaBehaviourKind::motivator, 0x52, at_ms(20), at_ms(2020)}));
  EXPECT_EQ(state().ears[0], kGreen);
  EXPECT_EQ(state().belt[0], kGreen);
  EXPECT_EQ(state().belt[7], kOff);
  EXPECT_EQ(state().left, (LekaMotor{1, 96}));  // turning left first
  EXPECT_EQ(state().right, (LekaMotor{0, 96}));
  EXPECT_EQ(car.firmware().summary(), "L-96 R+96 EARS 00FF00 00FF00 BELT 1/20 MOTIVATOR 0x52");
  car.run_until(at_ms(119));
  EXPECT_EQ(state().belt[0], kGreen);
  car.run_until(at_ms(120));
  EXPECT_EQ(state().belt[0], kOff);
  EXPECT_EQ(state().belt[1], kGreen);
  car.run_until(at_ms(510));
  EXPECT_GT(car.vehicle().pose().heading_rad, heading0 + 0.3);
  const double heading_510 = car.vehicle().pose().heading_rad;
  car.run_until(at_ms(520));
  EXPECT_EQ(state().left, (LekaMotor{0, 96}));  // then right
  EXPECT_EQ(state().right, (LekaMotor{1, 96}));
  car.run_until(at_ms(1010));
  EXPECT_LT(car.vehicle().pose().heading_rad, heading_510 - 0.2);
  car.run_until(at_ms(2010));
  EXPECT_TRUE(state().behaviour.has_value());
  car.run_until(at_ms(2020));
  EXPECT_FALSE(state().behaviour.has_value());
  EXPECT_EQ(state().ears[0], kBlue);  // the LEDs come back
  EXPECT_EQ(state().belt[7], kRed);
  EXPECT_EQ(state().belt[0], kOff);
  EXPECT_EQ(state().left, LekaMotor{});  // and the wheels stop
  EXPECT_EQ(chassis().left_pwm(), 0);
  EXPECT_EQ(state().counters.behaviours_started, 1u);
  EXPECT_EQ(state().counters.behaviours_interrupted, 0u);
  // It turned on the spot.
  car.run_until(at_ms(2500));
  EXPECT_NEAR(car.vehicle().pose().x_m, start.x_m, 0.01);
  EXPECT_NEAR(car.vehicle().pose().y_m, start.y_m, 0.01);
}

TEST_F(LekaTest, GuidanceBlinksItsNumberOfBeltLedsAndDoesNotMove) {
  send_and_pass(frame({leka::BeltAll{kRed}, leka::MotorAll{0, 50}}));
  send_and_pass(frame({leka::Guidance{0x43}}));  // pass at 20 ms
  ASSERT_TRUE(state().behaviour.has_value());
  EXPECT_EQ(state().behaviour->kind, LekaBehaviourKind::guidance);
  EXPECT_EQ(state().behaviour->ends, at_ms(3020));
  EXPECT_EQ(state().ears[0], kWhite);
  EXPECT_EQ(state().belt[2], kWhite);
  EXPECT_EQ(state().belt[3], kOff);
  EXPECT_EQ(state().left, (LekaMotor{0, 50}));  // the motors keep their command
  car.run_until(at_ms(519));
  EXPECT_EQ(state().belt[0], kWhite);
  car.run_until(at_ms(520));
  EXPECT_EQ(state().belt[0], kOff);
  EXPECT_EQ(state().ears[1], kOff);
  car.run_until(at_ms(1020));
  EXPECT_EQ(state().belt[0], kWhite);
  car.run_until(at_ms(3020));
  EXPECT_FALSE(state().behaviour.has_value());
  EXPECT_EQ(state().belt[0], kRed);
  EXPECT_EQ(state().belt[19], kRed);
  EXPECT_EQ(chassis().left_pwm(), 50);
}

TEST_F(LekaTest, ACommandEndsAPlayingBehaviourAndANewBehaviourReplacesIt) {
  send_and_pass(frame({leka::Motivator{0x51}}));
  car.run_until(at_ms(200));
  send_and_pass(frame({leka::EarSingle{0, kBlue}}));
  EXPECT_FALSE(state().behaviour.has_value());
  EXPECT_EQ(state().ears[0], kBlue);
  EXPECT_EQ(state().belt[1], kOff);
  EXPECT_EQ(state().left, LekaMotor{});  // the motivator's turn stops with it
  EXPECT_EQ(state().counters.behaviours_interrupted, 1u);

  send_and_pass(frame({leka::Guidance{0x41}}));
  send_and_pass(frame({leka::Motivator{0x53}}));
  ASSERT_TRUE(state().behaviour.has_value());
  EXPECT_EQ(state().behaviour->kind, LekaBehaviourKind::motivator);
  EXPECT_EQ(state().ears[0], kBlue);  // motivator 0x53 is blue too
  EXPECT_EQ(state().counters.behaviours_started, 3u);
  EXPECT_EQ(state().counters.behaviours_interrupted, 2u);

  // info does not interrupt.
  send_and_pass(kSeedInfo);
  EXPECT_TRUE(state().behaviour.has_value());
}

// ------------------------------------------------------------ fault, reject, ignore

TEST_F(LekaTest, FaultStopsTheMotorsAndRefusesMotionUntilCleared) {
  send_and_pass(frame({leka::MotorAll{0, 200}}));
  car.firmware().arm(Behaviour{"", When{at_ms(50), "", 1}, EnterFault{}});
  car.run_until(at_ms(49));
  EXPECT_EQ(chassis().left_pwm(), 200);
  car.run_until(at_ms(50));
  EXPECT_TRUE(car.firmware().in_fault());
  EXPECT_EQ(state().left, LekaMotor{});
  EXPECT_EQ(chassis().left_pwm(), 0);

  send_and_pass(frame({leka::MotorAll{0, 100}, leka::EarAll{kRed}, leka::Motivator{0x51},
                       leka::MotorLeft{0, 9}, leka::Info{}}));
  EXPECT_EQ(chassis().left_pwm(), 0);
  EXPECT_FALSE(state().behaviour.has_value());
  EXPECT_EQ(state().ears[0], kRed);  // LEDs still work
  EXPECT_EQ(state().counters.refused_in_fault, 3u);
  EXPECT_EQ(client->take_text(), "LEKA name=leka firmware=1.0.0 buffer=128 state=fault\r\n");
  EXPECT_EQ(car.firmware().summary(), "L+0 R+0 EARS FF0000 FF0000 BELT 0/20 FAULT");

  car.firmware().arm(Behaviour{"", When{}, ClearFault{}});
  send_and_pass(frame({leka::MotorAll{0, 100}}));
  EXPECT_FALSE(car.firmware().in_fault());
  EXPECT_EQ(chassis().left_pwm(), 100);
}

TEST_F(LekaTest, FaultEndsAMotivatorButNotAGuidance) {
  send_and_pass(frame({leka::Motivator{0x54}}));
  car.firmware().arm(Behaviour{"", When{}, EnterFault{}});
  car.run_for(milliseconds(10));
  EXPECT_FALSE(state().behaviour.has_value());
  EXPECT_EQ(chassis().right_pwm(), 0);
  send_and_pass(frame({leka::Guidance{0x42}}));
  EXPECT_TRUE(state().behaviour.has_value());
  EXPECT_EQ(state().belt[1], kWhite);
  EXPECT_EQ(chassis().right_pwm(), 0);
}

TEST_F(LekaTest, RejectedCommandsDoNotRunAndNothingIsAnswered) {
  car.firmware().arm(Behaviour{"", When{}, Reject{"motor", 1}});
  send_and_pass(frame({leka::MotorAll{0, 90}, leka::EarAll{kGreen}, leka::MotorLeft{0, 30}}));
  EXPECT_EQ(state().ears[0], kGreen);
  EXPECT_EQ(state().left, (LekaMotor{0, 30}));  // only the first motor command was refused
  EXPECT_EQ(state().right, LekaMotor{});
  EXPECT_EQ(car.firmware().stats().rejected, 1u);
  EXPECT_EQ(car.firmware().stats().ignored, 0u);

  car.firmware().arm(Behaviour{"", When{}, Reject{"info", 1}});
  send_and_pass(kSeedInfo);
  EXPECT_EQ(client->text(), "");
  EXPECT_EQ(car.firmware().stats().rejected, 2u);
}

TEST_F(LekaTest, IgnoredCommandsDoNotRunAndAreCountedAsIgnored) {
  car.firmware().arm(Behaviour{"", When{}, Ignore{"led", 2, std::nullopt}});
  send_and_pass(frame({leka::EarAll{kGreen}, leka::BeltAll{kGreen}, leka::BeltSingle{0, kRed}}));
  EXPECT_EQ(state().ears[0], kOff);
  EXPECT_EQ(state().belt[1], kOff);
  EXPECT_EQ(state().belt[0], kRed);
  EXPECT_EQ(car.firmware().stats().ignored, 2u);
  EXPECT_EQ(car.firmware().stats().rejected, 0u);
  EXPECT_EQ(state().counters.commands_run, 1u);
}

TEST_F(LekaTest, AfterFrameBehavioursCountEachCommandOfAGroup) {
  car.firmware().arm(Behaviour{"", When{std::nullopt, "led.ear.all", 1}, EnterFault{}});
  // The fault comes right after led.ear.all, so the motor command after it is refused.
  send_and_pass(frame({leka::EarAll{kGreen}, leka::MotorAll{0, 90}}));
  EXPECT_TRUE(car.firmware().in_fault());
  EXPECT_EQ(state().ears[0], kGreen);
  EXPECT_EQ(chassis().left_pwm(), 0);
  EXPECT_EQ(state().counters.refused_in_fault, 1u);
}

// ------------------------------------------------------------ connection

TEST_F(LekaTest, TheRobotKeepsDrivingAfterTheClientLeaves) {
  send_and_pass(frame({leka::MotorAll{0, 255}}));
  client->pipe->close();
  car.run_for(milliseconds(5));
  ASSERT_FALSE(car.firmware().connected());
  const double x0 = car.vehicle().pose().x_m;
  car.run_until(at_ms(500));
  EXPECT_GT(car.vehicle().pose().x_m, x0 + 0.05);
  EXPECT_EQ(chassis().left_pwm(), 255);
}

TEST(LekaFirmwareConnection, StopOnDisconnectStopsTheRobot) {
  LekaConfig config;
  config.stop_on_disconnect = true;
  auto car = make_car(config);
  auto client = car.connect();
  client->write(frame({leka::EarAll{kGreen}, leka::MotorAll{0, 255}}));
  car.run_until(at_ms(100));
  client->pipe->close();
  car.run_for(milliseconds(5));
  EXPECT_EQ(car.vehicle().differential()->left_pwm(), 0);
  EXPECT_EQ(car.firmware().state().ears[0], kGreen);
}

TEST_F(LekaTest, InfoWithNoClientIsDropped) {
  // Bytes already in the robot's buffer still run after the client left.
  client->write(concat({frame({leka::EarAll{kRed}}), kSeedInfo}));
  client->pipe->close();
  car.run_until(at_ms(10));
  EXPECT_EQ(state().ears[0], kRed);
  EXPECT_EQ(state().counters.info_answers, 1u);
  EXPECT_EQ(car.firmware().stats().bytes_out, 0u);
}

}  // namespace
}  // namespace hil::mocks::test
