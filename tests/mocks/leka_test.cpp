// The mock Leka Alpha firmware under the virtual-time driver: every command's
// effect, the 128-byte serial buffer and the main loop's timing, motion in
// the world, behaviours, bad input, the fault state and scripted behaviours.

#include "mocks/leka.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <array>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>

#include "link/protocol_adapter.hpp"
#include "protocol/common/overloaded.hpp"
#include "protocol/leka/codec.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"
#include "tests/protocol/leka/leka_generators.hpp"
#include "tests/support/hex.hpp"

namespace hil::mocks {
namespace {

namespace leka = protocol::leka;
using leka::Rgb;
using link::milliseconds;
using protocol::Bytes;

using Car = test::VirtualCar<LekaFirmware>;

constexpr Rgb kOff{};
constexpr Rgb kRed{255, 0, 0};
constexpr Rgb kGreen{0, 255, 0};
constexpr Rgb kBlue{0, 0, 255};
constexpr Rgb kWhite{255, 255, 255};

using test::at_ms;

using hil::test::hex;

Bytes frame(std::initializer_list<leka::Command> commands) {
  return leka::encode(leka::CommandGroup{commands});
}

Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const auto& p : parts)
    out.insert(out.end(), p.begin(), p.end());
  return out;
}

// The seed's three frames, byte for byte.
const Bytes kSeedInfo = hex("2A 2B 2C 2D 01 70 70");
const Bytes kSeedBeltRed = hex("2A 2B 2C 2D 05 15 00 FF 00 00 41");
const Bytes kSeedBelt20 =
    hex("2A 2B 2C 2D 64 15 00 33 00 00 15 01 66 00 00 15 02 99 00 00 15 03 CC 00 00 15 04 FF 00 00 "
        "15 05 00 00 00 15 06 00 33 00 15 07 00 66 00 15 08 00 99 00 15 09 00 CC 00 15 0A 00 FF 00 "
        "15 0B 00 00 00 15 0C 00 00 33 15 0D 00 00 66 15 0E 00 00 99 15 0F 00 00 CC 15 10 FF 00 00 "
        "15 11 00 FF 00 15 12 00 00 FF 15 13 FF FF FF A8");

const std::string kInfoLine = "LEKA name=leka firmware=1.0.0 buffer=128 state=ok\r\n";

// These tests watch the firmware's own serial buffer fill with partial
// frames and garbage, so the link passes bytes exactly as they are written
// (a frame-aware link would hold a partial frame itself until it is whole).
ServerOptions raw_link() {
  ServerOptions options;
  options.protocol = link::protocol_adapter("raw");
  return options;
}

Car make_car(LekaConfig config = {}, sim::VehicleDef vehicle = sim::leka_robot()) {
  return Car(
      std::move(vehicle),
      [config](sim::World& w, sim::Vehicle& v) {
        return std::make_unique<LekaFirmware>(w, v, config);
      },
      raw_link());
}

// A client connects at 0 ms (connected at 1 ms); bytes written at 1 ms are
// read by the main loop's pass at 10 ms.
struct LekaTest : ::testing::Test {
  Car car = make_car();
  std::shared_ptr<test::ClientEnd> client = car.connect();

  const LekaState& state() { return car.firmware().state(); }
  sim::DifferentialChassis& chassis() { return *car.vehicle().differential(); }
  /// Writes `bytes` now and runs the loop's next pass.
  void send_and_pass(const Bytes& bytes) {
    client->write(bytes);
    const auto period = car.firmware().config().loop_period;
    car.run_until(link::Time((car.now() / period + 1) * period));
  }
};

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

// ------------------------------------------------------------ bad input

TEST_F(LekaTest, BadChecksumIsDroppedSilentlyAndTheNextFrameStillRuns) {
  client->write(concat({hex("2A 2B 2C 2D 05 15 00 FF 00 00 42"), kSeedInfo}));
  car.run_until(at_ms(10));
  EXPECT_EQ(state().belt[0], kOff);
  EXPECT_EQ(state().counters.bad_checksum, 1u);
  EXPECT_EQ(car.firmware().stats().bad_frames, 1u);
  EXPECT_EQ(client->take_text(), kInfoLine);  // only the info, nothing for the bad frame
}

TEST_F(LekaTest, GarbageIsDroppedAndCounted) {
  client->write(protocol::to_bytes("hello robot"));
  car.run_until(at_ms(10));
  EXPECT_EQ(state().counters.garbage, 1u);
  EXPECT_EQ(car.firmware().stats().bad_frames, 1u);
  EXPECT_EQ(car.firmware().stats().frames_in, 0u);
  EXPECT_EQ(state().serial_buffered, 0u);
  EXPECT_EQ(client->text(), "");
  // Garbage right before a frame does not hide it.
  send_and_pass(concat({protocol::to_bytes("xx"), kSeedBeltRed}));
  EXPECT_EQ(state().belt[0], kRed);
  EXPECT_EQ(state().counters.garbage, 2u);
}

TEST_F(LekaTest, ShortGarbageWaitsForMoreBytesLikeTheRobotsParser) {
  // Under a minimal frame's 7 bytes the parser waits; then the garbage goes
  // with the frame that follows it.
  send_and_pass(protocol::to_bytes("junk"));
  EXPECT_EQ(state().serial_buffered, 4u);
  EXPECT_EQ(state().counters.garbage, 0u);
  send_and_pass(kSeedInfo);
  EXPECT_EQ(state().counters.garbage, 1u);
  EXPECT_EQ(client->take_text(), kInfoLine);
}

TEST_F(LekaTest, AStartSequenceSplitAcrossPassesSurvivesThePurge) {
  send_and_pass(concat({protocol::to_bytes("junkjunk"), hex("2A 2B")}));
  EXPECT_EQ(state().counters.garbage, 1u);
  EXPECT_EQ(state().serial_buffered, 2u);
  send_and_pass(hex("2C 2D 01 70 70"));
  EXPECT_EQ(client->take_text(), kInfoLine);
  EXPECT_EQ(state().counters.garbage, 1u);
}

TEST_F(LekaTest, OversizedLengthZeroLengthAndUnknownIdsAreDropped) {
  // Length 0x7B: a 123-byte group cannot fit the 128-byte buffer.
  send_and_pass(hex("2A 2B 2C 2D 7B"));
  EXPECT_EQ(state().counters.oversized, 1u);
  send_and_pass(hex("2A 2B 2C 2D 00"));
  EXPECT_EQ(state().counters.bad_format, 1u);
  send_and_pass(leka::frame_group(hex("99 01 02")));
  EXPECT_EQ(state().counters.unknown_code, 1u);
  // A known command cut short by the group's end.
  send_and_pass(leka::frame_group(hex("11 FF 00")));
  EXPECT_EQ(state().counters.bad_format, 2u);
  EXPECT_EQ(state().ears[0], kOff);
  EXPECT_EQ(car.firmware().stats().bad_frames, 4u);
  EXPECT_EQ(state().counters.commands_run, 0u);
  EXPECT_EQ(client->text(), "");
}

TEST_F(LekaTest, OutOfRangeValuesDropTheWholeFrame) {
  // Ear id 2 after a valid command: nothing of the group runs.
  send_and_pass(leka::frame_group(hex("13 FF 00 00 12 02 00 00 FF")));
  EXPECT_EQ(state().counters.bad_value, 1u);
  EXPECT_EQ(state().belt[0], kOff);
  send_and_pass(leka::frame_group(hex("21 02 80")));           // spin 2
  send_and_pass(leka::frame_group(hex("15 14 FF 00 00")));     // belt id 20
  send_and_pass(leka::frame_group(hex("50 56")));              // motivator id 0x56
  send_and_pass(leka::frame_group(hex("14 05 03 FF 00 00")));  // first > last
  EXPECT_EQ(state().counters.bad_value, 5u);
  EXPECT_EQ(chassis().left_pwm(), 0);
  EXPECT_FALSE(state().behaviour.has_value());
  EXPECT_EQ(state().counters.commands_run, 0u);
}

TEST(LekaFirmwareLenient, OutOfRangeValuesRunClampedWhenAccepted) {
  LekaConfig config;
  config.accept_out_of_range = true;
  auto car = make_car(config);
  auto client = car.connect();
  // Ear id 2 (no such ear), belt 18..25 (cut at 19), spin 2 (backward).
  client->write(leka::frame_group(hex("12 02 FF 00 00 14 12 19 00 FF 00 21 02 80")));
  car.run_until(at_ms(10));
  const auto& s = car.firmware().state();
  EXPECT_EQ(s.counters.tolerated, 1u);
  EXPECT_EQ(s.counters.bad_value, 0u);
  EXPECT_EQ(s.ears[0], kOff);
  EXPECT_EQ(s.belt[17], kOff);
  EXPECT_EQ(s.belt[18], kGreen);
  EXPECT_EQ(s.belt[19], kGreen);
  EXPECT_EQ(car.vehicle().differential()->left_pwm(), -128);
}

TEST(LekaFirmwareLenient, AWiderBeltLimitGivesMoreLeds) {
  LekaConfig config;
  config.max_belt_led_id = 0x19;  // the seed table's literal range
  auto car = make_car(config);
  auto client = car.connect();
  client->write(leka::encode(leka::CommandGroup{{leka::BeltSingle{25, kRed}}}, {0x19}));
  car.run_until(at_ms(10));
  ASSERT_EQ(car.firmware().state().belt.size(), 26u);
  EXPECT_EQ(car.firmware().state().belt[25], kRed);
}

// ------------------------------------------------------------ serial buffer

TEST_F(LekaTest, BytesBeyondTheFullSerialBufferAreLost) {
  // 106 + 4 * 7 = 134 bytes at once: 128 fit, the last 6 bytes are lost,
  // so the fourth info keeps only its first byte.
  client->write(concat({kSeedBelt20, kSeedInfo, kSeedInfo, kSeedInfo, kSeedInfo}));
  car.run_until(at_ms(9));
  EXPECT_EQ(state().counters.bytes_lost, 6u);
  EXPECT_EQ(state().serial_buffered, 128u);
  car.run_until(at_ms(10));
  EXPECT_EQ(state().belt[19], kWhite);
  EXPECT_EQ(client->take_text(), kInfoLine + kInfoLine + kInfoLine);
  EXPECT_EQ(state().serial_buffered, 1u);  // 2A: could start a frame
  // The next frame is found after that stray byte.
  send_and_pass(kSeedInfo);
  EXPECT_EQ(client->take_text(), kInfoLine);
  EXPECT_EQ(state().counters.garbage, 1u);
  EXPECT_EQ(car.firmware().stats().bytes_in, 134u + 7u);
}

TEST_F(LekaTest, EachPassEmptiesTheBufferSoPacedFramesAreNotLost) {
  client->write(kSeedBelt20);  // 1 ms
  car.run_until(at_ms(5));
  client->write(kSeedBelt20);  // 5 ms: the buffer still holds the first
  car.run_until(at_ms(10));
  EXPECT_EQ(state().counters.bytes_lost, 84u);
  EXPECT_EQ(state().serial_buffered, 22u);  // the second frame's head waits for the rest

  // Paced one frame per pass: nothing is lost.
  auto paced_car = make_car();
  auto paced = paced_car.connect();
  paced->write(kSeedBelt20);
  paced_car.run_until(at_ms(11));
  paced->write(kSeedBelt20);
  paced_car.run_until(at_ms(20));
  EXPECT_EQ(paced_car.firmware().state().counters.bytes_lost, 0u);
  EXPECT_EQ(paced_car.firmware().state().counters.commands_run, 40u);
}

TEST_F(LekaTest, AFrameCutByOverflowHoldsLaterFramesUntilItsLengthIsIn) {
  client->write(concat({kSeedBelt20, kSeedBelt20}));  // 22 bytes of the second frame fit
  car.run_until(at_ms(10));
  EXPECT_EQ(state().counters.bytes_lost, 84u);
  // Twelve infos (84 bytes) complete the cut frame's announced 106 bytes;
  // its checksum fails and the parser finds the infos inside it.
  for (int i = 0; i < 11; ++i)
    send_and_pass(kSeedInfo);
  EXPECT_EQ(client->text(), "");
  send_and_pass(kSeedInfo);
  EXPECT_EQ(state().counters.bad_checksum, 1u);
  std::string twelve;
  for (int i = 0; i < 12; ++i)
    twelve += kInfoLine;
  EXPECT_EQ(client->take_text(), twelve);
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

// ------------------------------------------------------------ properties

// What the LEDs and motors should show after a group of LED, motor and stop
// commands, worked out command by command from the profile's table.
struct Expected {
  std::array<Rgb, 2> ears{};
  std::array<Rgb, 20> belt{};
  LekaMotor left;
  LekaMotor right;

  void apply(const leka::Command& command) {
    std::visit(protocol::Overloaded{
                   [](const leka::Info&) {},
                   [](const leka::Motivator&) {},
                   [](const leka::Guidance&) {},
                   [&](const leka::StopLed&) { leds_off(); },
                   [&](const leka::StopMotor&) { left = right = {}; },
                   [&](const leka::StopRobot&) {
                     leds_off();
                     left = right = {};
                   },
                   [&](const leka::EarAll& c) {
                     ears = {c.color, c.color};
                   },
                   [&](const leka::EarRange& c) {
                     for (std::size_t i = c.first; i <= c.last; ++i)
                       ears.at(i) = c.color;
                   },
                   [&](const leka::EarSingle& c) { ears.at(c.led) = c.color; },
                   [&](const leka::BeltAll& c) { belt.fill(c.color); },
                   [&](const leka::BeltRange& c) {
                     for (std::size_t i = c.first; i <= c.last; ++i)
                       belt.at(i) = c.color;
                   },
                   [&](const leka::BeltSingle& c) { belt.at(c.led) = c.color; },
                   [&](const leka::MotorAll& c) {
                     left = right = {c.direction, c.speed};
                   },
                   [&](const leka::MotorDuo& c) {
                     left = {c.left_spin, c.left_speed};
                     right = {c.right_spin, c.right_speed};
                   },
                   [&](const leka::MotorLeft& c) {
                     left = {c.spin, c.speed};
                   },
                   [&](const leka::MotorRight& c) {
                     right = {c.spin, c.speed};
                   },
               },
               command);
  }
  void leds_off() {
    ears.fill(kOff);
    belt.fill(kOff);
  }
};

bool plays(const leka::Command& c) {
  return std::holds_alternative<leka::Motivator>(c) || std::holds_alternative<leka::Guidance>(c);
}

RC_GTEST_PROP(LekaFirmwareProperties, AGroupLeavesTheLedsAndMotorsItsCommandsSay,
              (leka::CommandGroup group)) {
  // Behaviours draw their own patterns; they have their own tests.
  std::erase_if(group.commands, plays);
  RC_PRE(!group.commands.empty());
  Expected expected;
  for (const auto& c : group.commands)
    expected.apply(c);

  auto car = make_car();
  auto client = car.connect();
  client->write(leka::encode(group));
  car.run_until(at_ms(10));
  const auto& s = car.firmware().state();
  RC_ASSERT(s.counters.commands_run == group.commands.size());
  RC_ASSERT(s.ears == expected.ears);
  RC_ASSERT(std::equal(s.belt.begin(), s.belt.end(), expected.belt.begin(), expected.belt.end()));
  RC_ASSERT(s.left == expected.left);
  RC_ASSERT(s.right == expected.right);
  RC_ASSERT(car.vehicle().differential()->left_pwm() == car.firmware().pwm_of(expected.left));
  RC_ASSERT(car.vehicle().differential()->right_pwm() == car.firmware().pwm_of(expected.right));
}

RC_GTEST_PROP(LekaFirmwareProperties, AnyInputOnlyEverGetsWholeInfoLinesBack, ()) {
  // Frames mixed with random bytes, written in random pieces at random times.
  const auto groups = *rc::gen::resize(8, rc::gen::arbitrary<std::vector<leka::CommandGroup>>());
  Bytes stream;
  for (const auto& g : groups) {
    const auto noise = *rc::gen::resize(20, rc::gen::arbitrary<Bytes>());
    stream.insert(stream.end(), noise.begin(), noise.end());
    const auto f = leka::encode(g);
    stream.insert(stream.end(), f.begin(), f.end());
  }
  auto car = make_car();
  auto client = car.connect();
  std::size_t at = 0;
  while (at < stream.size()) {
    const auto n = *rc::gen::inRange<std::size_t>(1, stream.size() - at + 1);
    client->write(Bytes(stream.begin() + static_cast<std::ptrdiff_t>(at),
                        stream.begin() + static_cast<std::ptrdiff_t>(at + n)));
    at += n;
    car.run_for(milliseconds(*rc::gen::inRange(1, 30)));
  }
  car.run_for(milliseconds(20));
  const auto& s = car.firmware().state();
  std::string lines;
  for (std::uint64_t i = 0; i < s.counters.info_answers; ++i)
    lines += kInfoLine;
  RC_ASSERT(client->text() == lines);
  RC_ASSERT(car.firmware().stats().bytes_in == stream.size());
  RC_ASSERT(s.serial_buffered <= 128u);
}

}  // namespace
}  // namespace hil::mocks
