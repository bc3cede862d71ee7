// The Arduino robot's mock firmware, profile `readme`, under the
// virtual-time driver: every
// command and answer, every NACK, the 96-byte bound, timed moves on the
// virtual clock, sensors, reset on connect and scripted behaviours.

#include "mocks/arduino.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "protocol/arduino/codec.hpp"
#include "tests/mocks/arduino_rig.hpp"

namespace hil::mocks {
namespace {

namespace arduino = protocol::arduino;
using link::milliseconds;
using link::seconds;
using test_arduino::heading_deg;
using test_arduino::Robot;

std::string request(std::uint8_t seq, arduino::Body body) {
  return arduino::encode_text(arduino::Message{seq, std::move(body)});
}
std::string ack(std::uint8_t seq, std::string info) {
  return request(seq, arduino::Ack{std::move(info)});
}
std::string nack(std::uint8_t seq, arduino::NackCode code) {
  return request(seq, arduino::Nack{code});
}
std::string nack(std::uint8_t seq, std::string text) {
  return request(seq, arduino::Nack{std::move(text)});
}

// The board of the README's examples (profile `readme`): these tests pin
// its answers; arduino_sketch_test.cpp covers the real sketch, the default.
ArduinoConfig readme_board() {
  ArduinoConfig config;
  config.dialect = arduino::Dialect::readme;
  return config;
}

// ---------------------------------------------------------------- answers

TEST(ArduinoFirmware, PingAnswersOkWithTheRequestsSeq) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask("^01|PING|*11$"), "^01|ACK|OK*4C$");
  EXPECT_EQ(robot.state().last_seq, 0x01);
}

TEST(ArduinoFirmware, EveryAnswerEchoesTheRequestsSeqOverTheWholeRange) {
  Robot robot(readme_board());
  for (int seq = 0; seq <= 0xFF; ++seq) {
    const auto s = static_cast<std::uint8_t>(seq);
    ASSERT_EQ(robot.ask(request(s, arduino::Ping{})), ack(s, "OK")) << "seq " << seq;
    ASSERT_EQ(robot.ask(request(s, arduino::Help{})),
              ack(s, std::string(ArduinoFirmware::help_text(arduino::Dialect::readme))));
  }
}

TEST(ArduinoFirmware, SetSpeedAnswersTheAppliedValue) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask("^02|V|160*63$"), ack(0x02, "160"));
  EXPECT_EQ(robot.state().pwm, 160);
  EXPECT_EQ(robot.ask(request(0x03, arduino::SetSpeed{0})), ack(0x03, "0"));
  EXPECT_EQ(robot.ask(request(0x04, arduino::SetSpeed{255})), ack(0x04, "255"));
  EXPECT_EQ(robot.state().pwm, 255);
  // A leading '+' and zeros are accepted; the answer is the value applied.
  EXPECT_EQ(robot.ask(arduino::frame_body("05|V|+090")), ack(0x05, "90"));
  EXPECT_EQ(robot.state().pwm, 90);
  // V alone moves nothing.
  EXPECT_EQ(robot.chassis().left_pwm(), 0);
  EXPECT_FALSE(robot.firmware().moving());
}

TEST(ArduinoFirmware, MoveAnswersOkAsTheMoveStartsAndDrivesBothSides) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask("^03|M|25*49$"), "^03|ACK|OK*4E$");
  EXPECT_EQ(robot.state().motion, ArduinoMotion::move);
  EXPECT_EQ(robot.state().motion_arg, 25);
  EXPECT_EQ(robot.chassis().left_pwm(), 140);
  EXPECT_EQ(robot.chassis().right_pwm(), 140);
  EXPECT_EQ(robot.ask(request(0x04, arduino::Move{-10})), ack(0x04, "OK"));
  EXPECT_EQ(robot.chassis().left_pwm(), -140);
  EXPECT_EQ(robot.chassis().right_pwm(), -140);
}

TEST(ArduinoFirmware, RotatePositiveTurnsRightAndNegativeLeft) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask(request(0x04, arduino::Rotate{90})), ack(0x04, "OK"));
  EXPECT_EQ(robot.state().motion, ArduinoMotion::rotate);
  EXPECT_EQ(robot.chassis().left_pwm(), 140);
  EXPECT_EQ(robot.chassis().right_pwm(), -140);
  EXPECT_EQ(robot.ask("^04|R|-90*72$"), ack(0x04, "OK"));
  EXPECT_EQ(robot.chassis().left_pwm(), -140);
  EXPECT_EQ(robot.chassis().right_pwm(), 140);
}

TEST(ArduinoFirmware, StopAnswersOkAndCutsTheMotors) {
  Robot robot(readme_board());
  robot.ask(request(0x01, arduino::Move{50}));
  robot.run_for(milliseconds(200));
  EXPECT_EQ(robot.ask("^07|S|*54$"), ack(0x07, "OK"));
  EXPECT_FALSE(robot.firmware().moving());
  EXPECT_EQ(robot.chassis().left_pwm(), 0);
  EXPECT_EQ(robot.chassis().right_pwm(), 0);
  // S when idle is answered the same.
  EXPECT_EQ(robot.ask(request(0x08, arduino::Stop{})), ack(0x08, "OK"));
}

TEST(ArduinoFirmware, StatusTellsIdleThePwmUptimeAndBattery) {
  Robot robot(readme_board());
  const Time booted = robot.state().booted_at;
  robot.run_until(booted + milliseconds(1234));
  const std::string answer = robot.ask("^08|STATUS|*1C$");
  const auto battery_mv = std::lround(robot.car->vehicle().battery().voltage_v * 1000);
  EXPECT_EQ(answer, ack(0x08, "IDLE PWM=140 UP_MS=1234 BAT_MV=" + std::to_string(battery_mv)));
  EXPECT_GT(battery_mv, 8000);  // a fresh 6 x AA pack
}

TEST(ArduinoFirmware, StatusWhileMovingNamesTheMoveAndTheTimeLeft) {
  Robot robot(readme_board());
  robot.ask(request(0x01, arduino::SetSpeed{200}));
  robot.ask(request(0x02, arduino::Rotate{-30}));  // 180 ms
  robot.run_until(robot.state().motion_started + milliseconds(100));
  const std::string answer = robot.ask(request(0x03, arduino::StatusRequest{}));
  const std::string text = robot.status_at(robot.now());
  EXPECT_EQ(text.rfind("MOVING R:-30 PWM=200 REM_MS=80 UP_MS=", 0), 0u) << text;
  EXPECT_EQ(answer, ack(0x03, text));
}

TEST(ArduinoFirmware, TheLongestStatusFitsTheBoardsFrame) {
  Robot robot(readme_board());
  robot.ask(request(0x01, arduino::SetSpeed{255}));
  robot.ask(request(0x02, arduino::Move{-32768}));
  const std::string answer = robot.ask(request(0xFF, arduino::StatusRequest{}));
  EXPECT_EQ(answer.rfind("^FF|ACK|MOVING M:-32768 PWM=255 REM_MS=589824 UP_MS=", 0), 0u) << answer;
  EXPECT_LE(answer.size(), arduino::kFirmwareMaxFrameBytes);
  EXPECT_LE(ack(0, std::string(ArduinoFirmware::help_text(arduino::Dialect::readme))).size(),
            arduino::kFirmwareMaxFrameBytes);
}

TEST(ArduinoFirmware, HelpListsTheCommands) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask(request(0x09, arduino::Help{})),
            ack(0x09, "PING STATUS V<pwm> M<cm> R<deg> S B I HELP"));
}

TEST(ArduinoFirmware, AFrameInPiecesAndLineEndsAfterItAreAnsweredOnce) {
  Robot robot(readme_board());
  const std::string frame = "^01|PING|*11$\r\n";
  for (const char c : frame) {
    robot.client->write(std::string_view(&c, 1));
    robot.run_for(Duration::zero());
  }
  EXPECT_EQ(robot.client->take_text(), "^01|ACK|OK*4C$");
  // The CR/LF run is skipped (and counted) when the next frame starts.
  EXPECT_EQ(robot.ask("^02|PING|*12$"), "^02|ACK|OK*4F$");
  EXPECT_EQ(robot.firmware().stats().frames_in, 2u);
  EXPECT_EQ(robot.firmware().stats().bad_frames, 1u);
}

TEST(ArduinoFirmware, SeveralFramesInOneWriteAreAnsweredInOrder) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask("^01|PING|*11$^02|V|160*63$^07|JUMP|*05$"),
            "^01|ACK|OK*4C$" + ack(0x02, "160") + "^07|NACK|BAD_CMD*52$");
}

// ---------------------------------------------------------------- NACKs

TEST(ArduinoFirmware, BadChecksumIsAnsweredBadCsAndNothingHappens) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask("^02|V|160*00$"), nack(0x02, arduino::NackCode::bad_cs));
  EXPECT_EQ(robot.ask("^2A|S|*00$"), "^2A|NACK|BAD_CS*7C$");
  EXPECT_EQ(robot.state().pwm, 140);
  // One flipped payload bit: a move that must not start.
  EXPECT_EQ(robot.ask("^03|M|35*49$"), nack(0x03, arduino::NackCode::bad_cs));
  EXPECT_FALSE(robot.firmware().moving());
  EXPECT_EQ(robot.firmware().stats().bad_frames, 3u);
  EXPECT_EQ(robot.firmware().stats().frames_in, 0u);
}

TEST(ArduinoFirmware, BadFormatIsAnsweredBadFmt) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask("^03|PING|x*6B$"), nack(0x03, arduino::NackCode::bad_fmt));
  EXPECT_EQ(robot.ask(arduino::frame_body("04|PING")), nack(0x04, arduino::NackCode::bad_fmt));
  EXPECT_EQ(robot.ask(arduino::frame_body("05|M|ten")), nack(0x05, arduino::NackCode::bad_fmt));
  EXPECT_EQ(robot.ask(arduino::frame_body("06|R|40000")), nack(0x06, arduino::NackCode::bad_fmt));
  EXPECT_EQ(robot.ask(arduino::frame_body("07|M|1|2")), nack(0x07, arduino::NackCode::bad_fmt));
  EXPECT_EQ(robot.ask("^08|S|$"), nack(0x08, arduino::NackCode::bad_fmt));  // no '*'
  EXPECT_FALSE(robot.firmware().moving());
}

TEST(ArduinoFirmware, BadSeqIsAnsweredBadSeqWithSeqZero) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask("^G1|PING|*66$"), "^00|NACK|BAD_SEQ*58$");
  EXPECT_EQ(robot.ask(arduino::frame_body("1|M|10")), nack(0x00, arduino::NackCode::bad_seq));
  EXPECT_FALSE(robot.firmware().moving());
}

TEST(ArduinoFirmware, UnknownCommandIsAnsweredBadCmd) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask("^07|JUMP|*05$"), "^07|NACK|BAD_CMD*52$");
  EXPECT_EQ(robot.ask(arduino::frame_body("08|ping|")), nack(0x08, arduino::NackCode::bad_cmd));
  EXPECT_EQ(robot.ask(arduino::frame_body("09|HISTORY|")), nack(0x09, arduino::NackCode::bad_cmd));
  // The board's own answer words are not requests it takes.
  EXPECT_EQ(robot.ask(ack(0x0A, "OK")), nack(0x0A, arduino::NackCode::bad_cmd));
  EXPECT_EQ(robot.ask(nack(0x0B, arduino::NackCode::bad_cs)),
            nack(0x0B, arduino::NackCode::bad_cmd));
}

TEST(ArduinoFirmware, BadSpeedIsAnsweredBadVAndKeepsTheSpeed) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask("^05|V|999*6A$"), "^05|NACK|BAD_V*4C$");
  EXPECT_EQ(robot.ask(arduino::frame_body("06|V|fast")), nack(0x06, arduino::NackCode::bad_v));
  EXPECT_EQ(robot.ask(arduino::frame_body("07|V|-1")), nack(0x07, arduino::NackCode::bad_v));
  EXPECT_EQ(robot.ask(arduino::frame_body("08|V|")), nack(0x08, arduino::NackCode::bad_v));
  EXPECT_EQ(robot.state().pwm, 140);
}

TEST(ArduinoFirmware, LowercaseChecksumIsTakenUnlessConfiguredStrict) {
  Robot lenient(readme_board());
  EXPECT_EQ(lenient.ask("^06|I|*4f$").rfind("^06|ACK|", 0), 0u);
  ArduinoConfig strict = readme_board();
  strict.accept_lowercase_checksum = false;
  Robot robot(strict);
  EXPECT_EQ(robot.ask("^06|I|*4f$"), nack(0x06, arduino::NackCode::bad_cs));
  EXPECT_EQ(robot.ask("^06|I|*4F$").rfind("^06|ACK|", 0), 0u);
}

// ---------------------------------------------------------------- frame bound

TEST(ArduinoFirmware, FramesOverNinetySixBytesAreDroppedWithoutAnAnswer) {
  Robot robot(readme_board());
  // ^01|M|<payload>*CS$ is 10 bytes plus the payload.
  const std::string at_bound = arduino::frame_body("01|M|" + std::string(86, 'x'));
  const std::string over = arduino::frame_body("02|M|" + std::string(87, 'x'));
  ASSERT_EQ(at_bound.size(), 96u);
  ASSERT_EQ(over.size(), 97u);
  // 96 bytes reach the parser (and are refused for their payload) ...
  EXPECT_EQ(robot.ask(at_bound), nack(0x01, arduino::NackCode::bad_fmt));
  // ... 97 never do: the client sees nothing at all.
  EXPECT_EQ(robot.ask(over), "");
  EXPECT_EQ(robot.ask(arduino::frame_body("03|JUMP" + std::string(200, 'J') + "|")), "");
  robot.run_for(seconds(5));
  EXPECT_EQ(robot.client->take_text(), "");
  // The board is listening again at the next '^'.
  EXPECT_EQ(robot.ask(request(0x04, arduino::Ping{})), ack(0x04, "OK"));
  EXPECT_GE(robot.firmware().stats().bad_frames, 3u);
}

TEST(ArduinoFirmware, AFrameCutShortByTheNextIsDroppedAndTheNextAnswered) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.ask("^01|M|25^02|PING|*12$"), ack(0x02, "OK"));
  EXPECT_FALSE(robot.firmware().moving());
}

// ---------------------------------------------------------------- motion

TEST(ArduinoFirmware, MoveLastsEighteenMillisecondsPerCentimetre) {
  Robot robot(readme_board());
  const sim::Pose start = robot.pose();
  ASSERT_EQ(robot.ask(request(0x01, arduino::Move{50})), ack(0x01, "OK"));
  const Time t0 = robot.state().motion_started;
  EXPECT_EQ(t0, robot.now());
  EXPECT_EQ(robot.state().motion_ends, t0 + milliseconds(900));

  robot.run_until(t0 + milliseconds(899));
  const std::string busy = robot.ask(request(0x02, arduino::StatusRequest{}));
  EXPECT_NE(busy.find("|MOVING M:50 PWM=140 REM_MS=1 "), std::string::npos) << busy;
  EXPECT_EQ(robot.chassis().left_pwm(), 140);

  robot.run_until(t0 + milliseconds(900));
  const std::string idle = robot.ask(request(0x03, arduino::StatusRequest{}));
  EXPECT_NE(idle.find("|IDLE PWM=140 "), std::string::npos) << idle;
  EXPECT_EQ(robot.chassis().left_pwm(), 0);
  EXPECT_EQ(robot.chassis().right_pwm(), 0);

  robot.run_for(seconds(1));  // coasts to a stop
  const sim::Pose end = robot.pose();
  EXPECT_NEAR(end.x_m - start.x_m, 0.50, 0.01);
  EXPECT_NEAR(end.y_m - start.y_m, 0.0, 0.005);
  EXPECT_NEAR(heading_deg(end) - heading_deg(start), 0.0, 1.0);
}

TEST(ArduinoFirmware, BackwardMoveDrivesBack) {
  Robot robot(readme_board());
  const sim::Pose start = robot.pose();
  robot.ask(request(0x01, arduino::Move{-30}));
  const Time t0 = robot.state().motion_started;
  EXPECT_EQ(robot.state().motion_ends, t0 + milliseconds(540));
  robot.run_until(t0 + seconds(2));
  EXPECT_NEAR(robot.pose().x_m - start.x_m, -0.30, 0.01);
}

TEST(ArduinoFirmware, RotateLastsSixMillisecondsPerDegree) {
  Robot robot(readme_board());
  const sim::Pose start = robot.pose();
  ASSERT_EQ(robot.ask(request(0x01, arduino::Rotate{90})), ack(0x01, "OK"));
  const Time t0 = robot.state().motion_started;
  robot.run_until(t0 + milliseconds(539));
  EXPECT_TRUE(robot.firmware().moving());
  EXPECT_NE(robot.ask(request(0x02, arduino::StatusRequest{})).find("|MOVING R:90 "),
            std::string::npos);
  robot.run_until(t0 + milliseconds(540));
  EXPECT_FALSE(robot.firmware().moving());
  EXPECT_NE(robot.ask(request(0x03, arduino::StatusRequest{})).find("|IDLE "), std::string::npos);
  robot.run_for(seconds(1));
  // Right is clockwise: the heading goes down by 90 degrees, on the spot.
  EXPECT_NEAR(heading_deg(robot.pose()) - heading_deg(start), -90.0, 2.0);
  EXPECT_NEAR(robot.pose().x_m, start.x_m, 0.01);
  EXPECT_NEAR(robot.pose().y_m, start.y_m, 0.01);

  robot.ask(request(0x04, arduino::Rotate{-45}));
  EXPECT_EQ(robot.state().motion_ends, robot.now() + milliseconds(270));
  robot.run_for(seconds(1));
  EXPECT_NEAR(heading_deg(robot.pose()) - heading_deg(start), -45.0, 2.0);
}

TEST(ArduinoFirmware, DurationDoesNotScaleWithSpeedSoAFasterMoveOvershoots) {
  Robot robot(readme_board());
  const sim::Pose start = robot.pose();
  robot.ask(request(0x01, arduino::SetSpeed{70}));
  robot.ask(request(0x02, arduino::Move{50}));
  EXPECT_EQ(robot.state().motion_ends - robot.state().motion_started, milliseconds(900));
  EXPECT_EQ(robot.chassis().left_pwm(), 70);
  robot.run_for(seconds(2));
  EXPECT_NEAR(robot.pose().x_m - start.x_m, 0.25, 0.01);  // half the PWM, half the way
}

TEST(ArduinoFirmware, ScaledDurationKeepsTheDistanceAtAnySpeed) {
  ArduinoConfig config = readme_board();
  config.scale_duration_with_pwm = true;
  Robot robot(config);
  const sim::Pose start = robot.pose();
  robot.ask(request(0x01, arduino::SetSpeed{70}));
  robot.ask(request(0x02, arduino::Move{50}));
  const Time t0 = robot.state().motion_started;
  EXPECT_EQ(robot.state().motion_ends, t0 + milliseconds(1800));
  robot.run_until(t0 + milliseconds(1799));
  EXPECT_TRUE(robot.firmware().moving());
  robot.run_until(t0 + milliseconds(1800));
  EXPECT_FALSE(robot.firmware().moving());
  robot.run_for(seconds(1));
  EXPECT_NEAR(robot.pose().x_m - start.x_m, 0.50, 0.01);
}

TEST(ArduinoFirmware, StopDuringAMoveHaltsTheRobotEarly) {
  Robot robot(readme_board());
  const sim::Pose start = robot.pose();
  robot.ask(request(0x01, arduino::Move{100}));  // 1.8 s
  robot.run_for(milliseconds(500));
  EXPECT_EQ(robot.ask(request(0x02, arduino::Stop{})), ack(0x02, "OK"));
  EXPECT_NE(robot.ask(request(0x03, arduino::StatusRequest{})).find("|IDLE "), std::string::npos);
  robot.run_for(seconds(3));
  // 0.5 s at 55.6 cm/s, as the ramps up and down cancel out.
  EXPECT_NEAR(robot.pose().x_m - start.x_m, 0.278, 0.01);
}

TEST(ArduinoFirmware, ANewMoveReplacesTheRunningOne) {
  Robot robot(readme_board());
  robot.ask(request(0x01, arduino::Move{100}));
  robot.run_for(milliseconds(300));
  robot.ask(request(0x02, arduino::Rotate{90}));
  EXPECT_EQ(robot.state().motion, ArduinoMotion::rotate);
  EXPECT_EQ(robot.state().motion_started, robot.now());
  EXPECT_EQ(robot.state().motion_ends, robot.now() + milliseconds(540));
  EXPECT_EQ(robot.chassis().left_pwm(), 140);
  EXPECT_EQ(robot.chassis().right_pwm(), -140);
  // M:0 is a move of nothing: it replaces the rotation and so stops.
  robot.run_for(milliseconds(100));
  EXPECT_EQ(robot.ask(request(0x03, arduino::Move{0})), ack(0x03, "OK"));
  EXPECT_FALSE(robot.firmware().moving());
  EXPECT_EQ(robot.chassis().left_pwm(), 0);
}

TEST(ArduinoFirmware, SpeedSetDuringAMoveAppliesToTheNextMove) {
  Robot robot(readme_board());
  robot.ask(request(0x01, arduino::Move{50}));
  robot.run_for(milliseconds(100));
  EXPECT_EQ(robot.ask(request(0x02, arduino::SetSpeed{200})), ack(0x02, "200"));
  EXPECT_EQ(robot.chassis().left_pwm(), 140);
  EXPECT_EQ(robot.state().motion_pwm, 140);
  EXPECT_NE(robot.ask(request(0x03, arduino::StatusRequest{})).find("MOVING M:50 PWM=200 "),
            std::string::npos);
  robot.ask(request(0x04, arduino::Move{50}));
  EXPECT_EQ(robot.chassis().left_pwm(), 200);
}

TEST(ArduinoFirmware, TheControlLoopRunsOnATenMillisecondGridOnlyWhileTheRobotMoves) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.firmware().next_wakeup(), std::nullopt);
  robot.run_until(Time(milliseconds(3)));
  robot.ask(request(0x01, arduino::Move{1}));  // 18 ms
  EXPECT_EQ(robot.firmware().next_wakeup(), Time(milliseconds(10)));
  robot.run_until(Time(milliseconds(20)));
  EXPECT_EQ(robot.firmware().next_wakeup(), Time(milliseconds(21)));  // the move's end
  robot.run_until(Time(milliseconds(21)));
  EXPECT_EQ(robot.chassis().left_pwm(), 0);
  EXPECT_EQ(robot.firmware().next_wakeup(), Time(milliseconds(30)));  // still rolling
  robot.run_for(seconds(1));
  EXPECT_EQ(robot.chassis().left_speed_mps(), 0.0);
  EXPECT_EQ(robot.firmware().next_wakeup(), std::nullopt);
}

// ---------------------------------------------------------------- sensors

sim::Pose place(Robot& robot, double x_m, double y_m, double heading_deg) {
  const sim::Pose pose{x_m, y_m, sim::deg_to_rad(heading_deg)};
  robot.car->vehicle().place(pose);
  robot.run_for(milliseconds(100));  // a fresh sonar ping
  return pose;
}

TEST(ArduinoFirmware, SonarReadsTheDistanceToAWallInWholeCentimetres) {
  Robot robot(readme_board());
  // Facing the east wall (x = 4 m); the sonar sits 0.1 m ahead of the centre.
  place(robot, 3.5, 1.0, 0);
  EXPECT_EQ(robot.ask("^05|B|*47$"), ack(0x05, "40"));
  place(robot, 3.0, 1.0, 0);
  EXPECT_EQ(robot.ask(request(0x06, arduino::SonarRead{})), ack(0x06, "90"));
}

TEST(ArduinoFirmware, SonarWithoutAnEchoReadsTheConfiguredValue) {
  Robot robot(readme_board(), test_arduino::open_field());
  EXPECT_EQ(robot.ask(request(0x01, arduino::SonarRead{})), ack(0x01, "0"));
  ArduinoConfig config = readme_board();
  config.no_echo_cm = 400;
  Robot other(config, test_arduino::open_field());
  EXPECT_EQ(other.ask(request(0x01, arduino::SonarRead{})), ack(0x01, "400"));
}

TEST(ArduinoFirmware, IrReadsBothSidesAsAnalogAndObstacle) {
  Robot robot(readme_board());
  // Heading east 0.15 m below the north wall: the left sensor, 6 cm left of
  // the axis and looking 30 degrees left, meets the wall after 0.18 m; the
  // right one sees nothing within its 0.30 m.
  place(robot, 3.0, 2.85, 0);
  EXPECT_EQ(robot.ask("^06|I|*4F$"), ack(0x06, "L=409,0 R=0,0"));  // 1023 * (1 - 0.18 / 0.3)
  // 0.08 m from the wall: under the 0.15 m threshold, the digital output trips.
  place(robot, 3.0, 2.9, 0);
  EXPECT_EQ(robot.ask(request(0x07, arduino::IrRead{})), ack(0x07, "L=750,1 R=0,0"));
  // Turned round along the same wall: now the right sensor sees it.
  place(robot, 3.0, 2.9, 180);
  EXPECT_EQ(robot.ask(request(0x08, arduino::IrRead{})), ack(0x08, "L=0,0 R=750,1"));
  // In the open, both read nothing.
  place(robot, 3.0, 1.0, 0);
  EXPECT_EQ(robot.ask(request(0x09, arduino::IrRead{})), ack(0x09, "L=0,0 R=0,0"));
}

// ---------------------------------------------------------------- silence

TEST(ArduinoFirmware, NeverSendsAnythingUnasked) {
  Robot robot(readme_board());
  robot.run_for(seconds(30));
  EXPECT_EQ(robot.client->take_text(), "");
  robot.ask(request(0x01, arduino::Move{40}));
  robot.run_for(seconds(60));  // the move ends with no "done" message
  EXPECT_EQ(robot.client->take_text(), "");
  EXPECT_EQ(robot.firmware().stats().frames_out, 1u);
  EXPECT_FALSE(robot.firmware().moving());
}

// ---------------------------------------------------------------- reset on connect

TEST(ArduinoFirmware, OpeningThePortResetsTheBoard) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.state().boots, 2u);  // power-on, then the client's open
  robot.ask(request(0x01, arduino::SetSpeed{200}));
  robot.ask(request(0x02, arduino::Move{500}));  // 9 s
  robot.run_for(seconds(1));
  robot.client->pipe->close();
  robot.run_for(milliseconds(500));
  // Closing the port does not reset the board: the move goes on, and ends
  // on time with no one connected.
  EXPECT_FALSE(robot.firmware().connected());
  EXPECT_TRUE(robot.firmware().moving());
  EXPECT_EQ(robot.chassis().left_pwm(), 200);
  const sim::Pose before = robot.pose();
  robot.run_for(milliseconds(500));
  EXPECT_GT(robot.pose().x_m, before.x_m + 0.3);

  auto second = robot.car->connect();
  robot.client = second;
  const Time opened = robot.state().booted_at;
  EXPECT_EQ(robot.state().boots, 3u);
  EXPECT_FALSE(robot.firmware().moving());
  EXPECT_EQ(robot.chassis().left_pwm(), 0);
  EXPECT_EQ(robot.state().pwm, 140);
  EXPECT_EQ(robot.state().last_seq, std::nullopt);
  robot.run_until(opened + milliseconds(250));
  const std::string status = robot.ask(request(0x03, arduino::StatusRequest{}));
  EXPECT_NE(status.find("|IDLE PWM=140 UP_MS=250 "), std::string::npos) << status;
}

TEST(ArduinoFirmware, APartialFrameDoesNotSurviveTheReset) {
  Robot robot(readme_board());
  robot.client->write("^01|PI");
  robot.run_for(milliseconds(5));
  robot.client->pipe->close();
  robot.run_for(milliseconds(50));
  robot.client = robot.car->connect();
  EXPECT_EQ(robot.ask("NG|*11$^02|PING|*12$"), ack(0x02, "OK"));
}

TEST(ArduinoFirmware, ABoardWithoutAutoResetKeepsItsStateAcrossSessions) {
  ArduinoConfig config = readme_board();
  config.reset_on_connect = false;
  Robot robot(config);
  EXPECT_EQ(robot.state().boots, 1u);
  robot.ask(request(0x01, arduino::SetSpeed{200}));
  robot.ask(request(0x02, arduino::Move{500}));
  robot.client->pipe->close();
  robot.run_for(milliseconds(100));
  robot.client = robot.car->connect();
  EXPECT_EQ(robot.state().boots, 1u);
  EXPECT_TRUE(robot.firmware().moving());
  EXPECT_EQ(robot.state().pwm, 200);
}

// ---------------------------------------------------------------- repeated requests

TEST(ArduinoFirmware, ARepeatedMoveRestartsItAsTheSketchDoes) {
  Robot robot(readme_board());
  const std::string move = request(0x05, arduino::Move{50});
  robot.ask(move);
  robot.run_for(milliseconds(400));
  EXPECT_EQ(robot.ask(move), ack(0x05, "OK"));
  EXPECT_EQ(robot.state().motion_started, robot.now());
}

TEST(ArduinoFirmware, ConfiguredToRepeatAnswersARepeatedRequestWithoutActingTwice) {
  ArduinoConfig config = readme_board();
  config.repeat_answer_for_repeated_request = true;
  Robot robot(config);
  const std::string move = request(0x05, arduino::Move{50});
  robot.ask(move);
  const Time t0 = robot.state().motion_started;
  robot.run_for(milliseconds(400));
  EXPECT_EQ(robot.ask(move), ack(0x05, "OK"));
  EXPECT_EQ(robot.state().motion_started, t0);
  // The same command under a new SEQ is a new request.
  EXPECT_EQ(robot.ask(request(0x06, arduino::Move{50})), ack(0x06, "OK"));
  EXPECT_EQ(robot.state().motion_started, robot.now());
  // A reset forgets the last request.
  robot.client->pipe->close();
  robot.run_for(milliseconds(50));
  robot.client = robot.car->connect();
  EXPECT_EQ(robot.ask(request(0x06, arduino::Move{50})), ack(0x06, "OK"));
  EXPECT_TRUE(robot.firmware().moving());
}

// ---------------------------------------------------------------- behaviours

TEST(ArduinoFirmware, FaultStopsTheMotorsAndRefusesMotionUntilCleared) {
  Robot robot(readme_board());
  robot.ask(request(0x01, arduino::Move{100}));
  robot.run_for(milliseconds(200));
  robot.firmware().arm(Behaviour{"", When{}, EnterFault{}});
  robot.run_for(milliseconds(1));
  EXPECT_TRUE(robot.firmware().in_fault());
  EXPECT_FALSE(robot.firmware().moving());
  EXPECT_EQ(robot.chassis().left_pwm(), 0);

  EXPECT_EQ(robot.ask(request(0x02, arduino::SetSpeed{100})), nack(0x02, "FAULT"));
  EXPECT_EQ(robot.ask(request(0x03, arduino::Move{10})), nack(0x03, "FAULT"));
  EXPECT_EQ(robot.ask(request(0x04, arduino::Rotate{10})), nack(0x04, "FAULT"));
  EXPECT_EQ(robot.state().pwm, 140);
  EXPECT_EQ(robot.chassis().left_pwm(), 0);
  // Queries and S still answer.
  EXPECT_EQ(robot.ask(request(0x05, arduino::Ping{})), ack(0x05, "OK"));
  EXPECT_NE(robot.ask(request(0x06, arduino::StatusRequest{})).find("|FAULT PWM=140 "),
            std::string::npos);
  EXPECT_EQ(robot.ask(request(0x07, arduino::SonarRead{})).rfind("^07|ACK|", 0), 0u);
  EXPECT_EQ(robot.ask(request(0x08, arduino::IrRead{})).rfind("^08|ACK|L=", 0), 0u);
  EXPECT_EQ(robot.ask(request(0x09, arduino::Help{})).rfind("^09|ACK|PING", 0), 0u);
  EXPECT_EQ(robot.ask(request(0x0A, arduino::Stop{})), ack(0x0A, "OK"));
  EXPECT_EQ(robot.firmware().summary(), "FAULT PWM 140");

  robot.firmware().arm(Behaviour{"", When{}, ClearFault{}});
  robot.run_for(milliseconds(1));
  EXPECT_EQ(robot.ask(request(0x0B, arduino::Move{10})), ack(0x0B, "OK"));
  EXPECT_TRUE(robot.firmware().moving());
}

TEST(ArduinoFirmware, AFaultOutlastsAResetAndUsesTheConfiguredCode) {
  ArduinoConfig config = readme_board();
  config.fault_code = "MOTOR_FAULT";
  Robot robot(config);
  robot.firmware().arm(Behaviour{"", When{std::nullopt, "M", 1}, EnterFault{}});
  // The fault comes after the M it follows was answered and started.
  EXPECT_EQ(robot.ask(request(0x01, arduino::Move{10})), ack(0x01, "OK"));
  EXPECT_TRUE(robot.firmware().in_fault());
  EXPECT_FALSE(robot.firmware().moving());
  robot.client->pipe->close();
  robot.run_for(milliseconds(50));
  robot.client = robot.car->connect();
  EXPECT_EQ(robot.ask(request(0x02, arduino::Move{10})), nack(0x02, "MOTOR_FAULT"));
}

TEST(ArduinoFirmware, RejectAnswersBusyWithTheSeqAndHasNoEffect) {
  Robot robot(readme_board());
  robot.firmware().arm(Behaviour{"", When{}, Reject{"M", 2}});
  robot.run_for(milliseconds(1));
  EXPECT_EQ(robot.ask(request(0x01, arduino::Move{10})), nack(0x01, "BUSY"));
  EXPECT_EQ(robot.ask(request(0x02, arduino::Ping{})), ack(0x02, "OK"));
  EXPECT_EQ(robot.ask(request(0x03, arduino::Move{10})), nack(0x03, "BUSY"));
  EXPECT_FALSE(robot.firmware().moving());
  EXPECT_EQ(robot.ask(request(0x04, arduino::Move{10})), ack(0x04, "OK"));
  EXPECT_EQ(robot.firmware().stats().rejected, 2u);

  ArduinoConfig config = readme_board();
  config.reject_code = "OUT_OF_RANGE";
  Robot other(config);
  other.firmware().arm(Behaviour{"", When{}, Reject{"", 1}});
  other.run_for(milliseconds(1));
  EXPECT_EQ(other.ask("^04|R|-90*72$"), "^04|NACK|OUT_OF_RANGE*1B$");
}

TEST(ArduinoFirmware, IgnoreSwallowsCommandsWithoutAnAnswerOrAnEffect) {
  Robot robot(readme_board());
  robot.firmware().arm(Behaviour{"", When{}, Ignore{"V", 1, std::nullopt}});
  robot.run_for(milliseconds(1));
  EXPECT_EQ(robot.ask(request(0x01, arduino::SetSpeed{200})), "");
  EXPECT_EQ(robot.state().pwm, 140);
  EXPECT_EQ(robot.ask(request(0x02, arduino::SetSpeed{200})), ack(0x02, "200"));

  robot.firmware().arm(Behaviour{"", When{}, Ignore{"", std::nullopt, milliseconds(500)}});
  robot.run_for(milliseconds(1));
  EXPECT_EQ(robot.ask(request(0x03, arduino::Move{10})), "");
  EXPECT_EQ(robot.ask(request(0x04, arduino::Ping{})), "");
  EXPECT_FALSE(robot.firmware().moving());
  // Frames the parser refuses are answered before any command is looked at.
  EXPECT_EQ(robot.ask("^05|PING|*00$"), nack(0x05, arduino::NackCode::bad_cs));
  robot.run_for(milliseconds(500));
  EXPECT_EQ(robot.ask(request(0x06, arduino::Ping{})), ack(0x06, "OK"));
  EXPECT_EQ(robot.firmware().stats().ignored, 3u);
}

// ---------------------------------------------------------------- construction

TEST(ArduinoFirmware, RefusesAVehicleWithoutADifferentialChassis) {
  sim::World world(sim::WorldDef{});
  sim::Vehicle& logi = world.add_vehicle(sim::logi_car());
  EXPECT_THROW(std::make_unique<ArduinoFirmware>(world, logi), std::invalid_argument);
}

TEST(ArduinoFirmware, RefusesConfigValuesOutOfRange) {
  sim::World world(sim::WorldDef{});
  sim::Vehicle& robot = world.add_vehicle(sim::arduino_robot());
  const auto refuses = [&](auto change) {
    ArduinoConfig config = readme_board();
    change(config);
    EXPECT_THROW(std::make_unique<ArduinoFirmware>(world, robot, config), std::invalid_argument);
  };
  refuses([](ArduinoConfig& c) { c.base_pwm = 256; });
  refuses([](ArduinoConfig& c) { c.ms_per_cm = 0; });
  refuses([](ArduinoConfig& c) { c.ms_per_deg = -6; });
  refuses([](ArduinoConfig& c) { c.fault_code = ""; });
  refuses([](ArduinoConfig& c) { c.reject_code = "A|B"; });
  refuses([](ArduinoConfig& c) { c.max_frame_bytes = 9; });
  refuses([](ArduinoConfig& c) { c.control_period = Duration::zero(); });
  EXPECT_NO_THROW(std::make_unique<ArduinoFirmware>(world, robot, ArduinoConfig{}));
}

TEST(ArduinoFirmware, SummaryShowsWhatTheRobotDoes) {
  Robot robot(readme_board());
  EXPECT_EQ(robot.firmware().protocol(), "arduino");
  EXPECT_EQ(robot.firmware().summary(), "IDLE PWM 140");
  robot.ask(request(0x01, arduino::Rotate{-45}));
  EXPECT_EQ(robot.firmware().summary(), "MOVING R:-45 PWM 140");
}

}  // namespace
}  // namespace hil::mocks
