// ACK texts to typed replies, in both dialects. The `firmware` vectors are
// the texts the real sketch writes (arduino.ino of
// andrii-mazurchuk/arduino_robot_steering- at 8dcfab0); the `readme` ones
// are what hil's readme profile answers.

#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "protocol/arduino/reply.hpp"

namespace hil::protocol::arduino {
namespace {

std::optional<Reply> sketch(const Body& request, std::string_view info) {
  return parse_reply(Dialect::firmware, request, info);
}
std::optional<Reply> readme(const Body& request, std::string_view info) {
  return parse_reply(Dialect::readme, request, info);
}

TEST(ArduinoReplies, TheSketchsTextsAreTyped) {
  EXPECT_EQ(sketch(Ping{}, "PONG"), Reply{PongReply{}});
  EXPECT_EQ(sketch(SetSpeed{160}, "OK"), Reply{DoneReply{}});
  EXPECT_EQ(sketch(Move{20}, "ACCEPTED"), Reply{DoneReply{}});
  EXPECT_EQ(sketch(Rotate{-90}, "ACCEPTED"), Reply{DoneReply{}});
  EXPECT_EQ(sketch(Stop{}, "STOPPED"), Reply{DoneReply{}});
  EXPECT_EQ(sketch(SonarRead{}, "B:232"), Reply{SonarReply{232}});
  EXPECT_EQ(sketch(SonarRead{}, "B:0"), Reply{SonarReply{0}});  // no echo within 30 ms
  EXPECT_EQ(sketch(IrRead{}, "I:AL=512,AR=1023,DL=0,DR=1"),
            (Reply{IrReply{512, 1023, false, true}}));
  EXPECT_EQ(sketch(Help{}, "CMDS:PING,HELP,STATUS,V,M,R,S,B,I"),
            (Reply{HelpReply{{"PING", "HELP", "STATUS", "V", "M", "R", "S", "B", "I"}}}));
}

TEST(ArduinoReplies, TheSketchsStatusInEachMotion) {
  const StatusReply idle{.pwm = 160, .dir = "stop"};
  EXPECT_EQ(sketch(StatusRequest{}, "STATUS:V=160,DIR=stop,MOT:IDLE"), Reply{idle});

  const StatusReply move{.pwm = 200, .motion = MotionKind::move, .time_left_ms = 342, .dir = "rev"};
  EXPECT_EQ(sketch(StatusRequest{}, "STATUS:V=200,DIR=rev,MOT:MOVE,tleft:342"), Reply{move});

  const StatusReply rot{.pwm = 0, .motion = MotionKind::rotate, .time_left_ms = 0, .dir = "stop"};
  EXPECT_EQ(sketch(StatusRequest{}, "STATUS:V=0,DIR=stop,MOT:ROT,tleft:0"), Reply{rot});
}

TEST(ArduinoReplies, TheReadmeBoardsTextsAreTheSameTypes) {
  EXPECT_EQ(readme(Ping{}, "OK"), Reply{PongReply{}});
  EXPECT_EQ(readme(SetSpeed{160}, "160"), Reply{DoneReply{160}});
  EXPECT_EQ(readme(Move{20}, "OK"), Reply{DoneReply{}});
  EXPECT_EQ(readme(SonarRead{}, "232"), Reply{SonarReply{232}});
  EXPECT_EQ(readme(IrRead{}, "L=512,0 R=1023,1"), (Reply{IrReply{512, 1023, false, true}}));
  EXPECT_EQ(readme(Help{}, "PING STATUS V<pwm> M<cm> R<deg> S B I HELP"),
            (Reply{HelpReply{{"PING", "STATUS", "V", "M", "R", "S", "B", "I", "HELP"}}}));

  const StatusReply moving{.pwm = 160,
                           .motion = MotionKind::move,
                           .time_left_ms = 15,
                           .motion_arg = -20,
                           .uptime_ms = 4000,
                           .battery_mv = 7400};
  EXPECT_EQ(readme(StatusRequest{}, "MOVING M:-20 PWM=160 REM_MS=15 UP_MS=4000 BAT_MV=7400"),
            Reply{moving});
  const StatusReply fault{
      .pwm = 0, .motion = MotionKind::fault, .uptime_ms = 1, .battery_mv = 6000};
  EXPECT_EQ(readme(StatusRequest{}, "FAULT PWM=0 UP_MS=1 BAT_MV=6000"), Reply{fault});
}

// A text the dialect does not answer that request with is not typed: the
// caller keeps the raw ACK text and knows the board is not the one it expects.
TEST(ArduinoReplies, TheOtherDialectsTextsAreNotTyped) {
  EXPECT_EQ(sketch(Ping{}, "OK"), std::nullopt);
  EXPECT_EQ(sketch(SonarRead{}, "232"), std::nullopt);
  EXPECT_EQ(sketch(StatusRequest{}, "IDLE PWM=0 UP_MS=1 BAT_MV=7400"), std::nullopt);
  EXPECT_EQ(sketch(SetSpeed{1}, "1"), std::nullopt);
  EXPECT_EQ(readme(SonarRead{}, "B:232"), std::nullopt);
  EXPECT_EQ(readme(StatusRequest{}, "STATUS:V=160,DIR=stop,MOT:IDLE"), std::nullopt);
  EXPECT_EQ(readme(IrRead{}, "I:AL=512,AR=1023,DL=0,DR=1"), std::nullopt);
}

TEST(ArduinoReplies, MalformedTextsAreNotTyped) {
  for (std::string_view bad :
       {"STATUS:V=256,DIR=stop,MOT:IDLE", "STATUS:V=1,DIR=up,MOT:IDLE",
        "STATUS:V=1,DIR=fwd,MOT:MOVE", "STATUS:V=1,DIR=fwd,MOT:RUN,tleft:3", "STATUS:", ""}) {
    EXPECT_EQ(sketch(StatusRequest{}, bad), std::nullopt) << bad;
  }
  for (std::string_view bad :
       {"I:AL=1024,AR=0,DL=0,DR=0", "I:AL=1,AR=0,DL=2,DR=0", "I:AL=1,AR=0"}) {
    EXPECT_EQ(sketch(IrRead{}, bad), std::nullopt) << bad;
  }
  EXPECT_EQ(sketch(SonarRead{}, "B:-1"), std::nullopt);
  EXPECT_EQ(readme(StatusRequest{}, "IDLE UP_MS=1"), std::nullopt);  // no PWM
  EXPECT_EQ(readme(StatusRequest{}, "IDLE PWM=1 SPEED=3"), std::nullopt);
}

}  // namespace
}  // namespace hil::protocol::arduino
