// The Arduino mock as the real sketch (dialect `firmware`): the real
// RobotClient's frames in, the real board's replies out, byte for byte
// (andrii-mazurchuk/arduino_robot_steering- at 8dcfab0; the facts are in
// docs/protocols/arduino.md, "Profiles").

#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "mocks/arduino.hpp"
#include "protocol/arduino/sketch.hpp"
#include "tests/mocks/arduino_rig.hpp"

namespace hil::mocks {
namespace {

namespace arduino = protocol::arduino;
using link::milliseconds;
using test_arduino::Robot;

ArduinoConfig sketch_config() {
  ArduinoConfig config;
  config.dialect = arduino::Dialect::firmware;
  return config;
}

struct Board : Robot {
  Board() : Robot(sketch_config()) {}
  explicit Board(sim::WorldDef world) : Robot(sketch_config(), std::move(world)) {}
};

std::string ack(std::string_view seq, std::string_view text) {
  return arduino::sketch_frame(seq, "ACK", text);
}
std::string nack(std::string_view seq, std::string_view text) {
  return arduino::sketch_frame(seq, "NACK", text);
}

TEST(ArduinoSketchFirmware, TheRealClientsPingIsAnsweredPong) {
  Board board;
  EXPECT_EQ(board.ask("^01|PING| *31$"), "^01|ACK|PONG*5E$");
  EXPECT_EQ(board.state().last_seq, 0x01);
}

TEST(ArduinoSketchFirmware, TheReadmesEmptyPayloadIsBadFormat) {
  Board board;
  EXPECT_EQ(board.ask("^01|PING|*11$"), "^01|NACK|BAD_FMT*41$");
  EXPECT_EQ(board.ask("^05|B|*47$"), nack("05", "BAD_FMT"));
  EXPECT_EQ(board.firmware().stats().bad_frames, 2u);
}

TEST(ArduinoSketchFirmware, EveryCommandOfTheRealCliGetsTheBoardsReply) {
  // The real CLI's run: PING V:160 M:20 B I STATUS S V:999 HELP.
  Board board;
  EXPECT_EQ(board.ask("^01|PING| *31$"), ack("01", "PONG"));
  EXPECT_EQ(board.ask("^02|V|160*63$"), ack("02", "OK"));
  EXPECT_EQ(board.state().pwm, 160);
  EXPECT_EQ(board.ask(arduino::sketch_frame("03", "M", "20")), ack("03", "ACCEPTED"));
  EXPECT_EQ(board.state().motion, ArduinoMotion::move);
  EXPECT_EQ(board.ask("^05|B| *67$").substr(0, 10), "^05|ACK|B:");
  EXPECT_EQ(board.ask(arduino::sketch_frame("06", "I", " ")).substr(0, 13), "^06|ACK|I:AL=");
  // 20 cm at 18 ms/cm: 360 ms, none of it gone yet.
  EXPECT_EQ(board.ask(arduino::sketch_frame("07", "STATUS", " ")),
            ack("07", "STATUS:V=160,DIR=fwd,MOT:MOVE,tleft:360"));
  EXPECT_EQ(board.ask(arduino::sketch_frame("08", "S", " ")), ack("08", "STOPPED"));
  EXPECT_FALSE(board.firmware().moving());
  EXPECT_EQ(board.ask(arduino::sketch_frame("09", "V", "999")), nack("09", "BAD_V"));
  EXPECT_EQ(board.ask(arduino::sketch_frame("0A", "HELP", " ")),
            ack("0A", "CMDS:PING,HELP,STATUS,V,M,R,S,B,I"));
}

TEST(ArduinoSketchFirmware, StatusShowsTheDirectionOfEachKindOfMove) {
  Board board;
  EXPECT_EQ(board.ask(arduino::sketch_frame("01", "STATUS", " ")),
            ack("01", "STATUS:V=140,DIR=stop,MOT:IDLE"));
  board.ask(arduino::sketch_frame("02", "M", "-10"));
  board.run_for(milliseconds(100));
  EXPECT_EQ(board.ask(arduino::sketch_frame("03", "STATUS", " ")),
            ack("03", "STATUS:V=140,DIR=rev,MOT:MOVE,tleft:80"));
  // A rotation replaces the move; the sketch's direction is then "stop".
  board.ask(arduino::sketch_frame("04", "R", "90"));
  EXPECT_EQ(board.ask(arduino::sketch_frame("05", "STATUS", " ")),
            ack("05", "STATUS:V=140,DIR=stop,MOT:ROT,tleft:540"));
  board.ask(arduino::sketch_frame("06", "M", "5"));
  board.run_for(milliseconds(90));  // 5 cm: 90 ms, then the move is over
  EXPECT_EQ(board.ask(arduino::sketch_frame("07", "STATUS", " ")),
            ack("07", "STATUS:V=140,DIR=stop,MOT:IDLE"));
}

TEST(ArduinoSketchFirmware, NumbersAreReadWithAtolAndMovesHaveNoRangeCheck) {
  Board board;
  // "abc" reads 0: a valid speed.
  EXPECT_EQ(board.ask(arduino::sketch_frame("01", "V", "abc")), ack("01", "OK"));
  EXPECT_EQ(board.state().pwm, 0);
  EXPECT_EQ(board.ask(arduino::sketch_frame("02", "V", "-1")), nack("02", "BAD_V"));
  EXPECT_EQ(board.ask(arduino::sketch_frame("03", "V", "200rpm")), ack("03", "OK"));
  EXPECT_EQ(board.state().pwm, 200);
  // A move far beyond the readme dialect's 16-bit range is accepted.
  EXPECT_EQ(board.ask(arduino::sketch_frame("04", "M", "100000")), ack("04", "ACCEPTED"));
  EXPECT_EQ(board.state().motion_arg, 100000);
}

TEST(ArduinoSketchFirmware, CommandsAreCaseInsensitiveAndUnknownOnesAreBadCmd) {
  Board board;
  EXPECT_EQ(board.ask("^0a|ping| *61$"), "^0a|ACK|PONG*0E$");
  EXPECT_EQ(board.ask(arduino::sketch_frame("0B", "Go", " ")), nack("0B", "BAD_CMD"));
  // The board's own words are not requests it knows.
  EXPECT_EQ(board.ask(arduino::sketch_frame("0C", "ACK", "OK")), nack("0C", "BAD_CMD"));
}

TEST(ArduinoSketchFirmware, MalformedFramesGetNoAnswerAndRefusalsEchoWhatTheBoardEchoes) {
  Board board;
  const std::pair<const char*, const char*> frames_and_answers[] = {
      {"^1*00$", ""},
      {"^01|V|1*0*63$", ""},
      {"^zz|PING| *00$", "^zz|NACK|BAD_CS*0F$"},
      {"^G1|PING| *46$", "^00|NACK|BAD_SEQ*58$"},
  };
  for (const auto& [frame, answer] : frames_and_answers)
    EXPECT_EQ(board.ask(frame), answer) << frame;
  EXPECT_EQ(board.firmware().stats().bad_frames, 4u);
  EXPECT_EQ(board.firmware().stats().frames_in, 0u);
}

TEST(ArduinoSketchFirmware, NoEchoReadsBZero) {
  Board board(test_arduino::open_field());
  EXPECT_EQ(board.ask("^05|B| *67$"), "^05|ACK|B:0*04$");
}

TEST(ArduinoSketchFirmware, TheSonarTruncatesToWholeCentimetres) {
  Board board;
  // Facing the east wall (x = 4 m) from 3.5 m; the sonar is 0.1 m ahead.
  board.car->vehicle().place(sim::Pose{3.5, 1.0, 0});
  board.run_for(milliseconds(100));
  EXPECT_EQ(board.ask("^05|B| *67$"), ack("05", "B:40"));
  board.car->vehicle().place(sim::Pose{3.495, 1.0, 0});  // 40.5 cm: still 40
  board.run_for(milliseconds(100));
  EXPECT_EQ(board.ask("^06|B| *64$"), ack("06", "B:40"));
}

// A firmware's processing time holds each answer back by exactly that
// long; a client that sends its next request before the answer to the last
// one gets both answers, in order, each that long after its request.
TEST(ArduinoSketchFirmware, AReplyLatencyDelaysEachAnswerAndPipelinedRequestsQueueBehind) {
  Board board;
  board.firmware().set_reply_latency(milliseconds(5));
  const Time t0 = board.now();
  board.client->write("^01|PING| *31$");
  board.run_for(milliseconds(2));
  EXPECT_EQ(board.client->take_text(), "") << "still being worked out at 2 ms";
  board.client->write("^02|PING| *32$");
  board.run_until(t0 + milliseconds(5) - std::chrono::nanoseconds(1));
  EXPECT_EQ(board.client->take_text(), "");
  board.run_until(t0 + milliseconds(5));
  EXPECT_EQ(board.client->take_text(), ack("01", "PONG"));
  board.run_until(t0 + milliseconds(7) - std::chrono::nanoseconds(1));
  EXPECT_EQ(board.client->take_text(), "");
  board.run_until(t0 + milliseconds(7));
  EXPECT_EQ(board.client->take_text(), ack("02", "PONG"));
  EXPECT_EQ(board.firmware().reply_latency(), milliseconds(5));
}

}  // namespace
}  // namespace hil::mocks
