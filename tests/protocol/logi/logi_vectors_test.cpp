// Every complete frame the LOGI specification lists (its button-to-command
// table) is a test vector: encode must produce it byte for byte, and decode
// must give the message back.

#include <gtest/gtest.h>

#include "protocol/common/car_profile.hpp"
#include "protocol/logi/codec.hpp"
#include "tests/protocol/decoder_test_support.hpp"

namespace hil::protocol::logi {
namespace {

using Vector = test::TextVector<Message>;

const Vector kSpecFrames[] = {
    {"LOGI:MD:MAN:0C#", SetMode{Mode::manual}},
    {"LOGI:MD:AUTO:69#", SetMode{Mode::automatic}},
    {"LOGI:SP:030:D5#", SetSpeed{30}},
    {"LOGI:SP:050:D7#", SetSpeed{50}},
    {"LOGI:SP:080:DA#", SetSpeed{80}},
    {"LOGI:GS:001:CA#", SetStation{1}},
    {"LOGI:GS:002:CB#", SetStation{2}},
    {"LOGI:ST:RUN:3B#", SetRun{true}},
    {"LOGI:ST:STOP:8C#", SetRun{false}},
    {"LOGI:MV:FWD:23#", Move{Direction::fwd}},
    {"LOGI:MV:BWD:1F#", Move{Direction::bwd}},
    {"LOGI:MV:LEFT:6D#", Move{Direction::left}},
    {"LOGI:MV:RIGHT:C0#", Move{Direction::right}},
    {"LOGI:MV:LF:D4#", Move{Direction::lf}},
    {"LOGI:MV:RF:DA#", Move{Direction::rf}},
    {"LOGI:MV:LB:D0#", Move{Direction::lb}},
    {"LOGI:MV:RB:D6#", Move{Direction::rb}},
    {"LOGI:MV:CW:DC#", Move{Direction::cw}},
    {"LOGI:MV:CCW:1F#", Move{Direction::ccw}},
    {"LOGI:MV:STOP:88#", Move{Direction::stop}},
};

TEST(LogiVectors, ThereAreTwentySpecFrames) {
  EXPECT_EQ(std::size(kSpecFrames), 20u);
}

TEST(LogiVectors, EncodeReproducesEverySpecFrame) {
  for (const auto& v : kSpecFrames)
    EXPECT_EQ(encode_text(v.message), v.frame) << describe(v.message);
}

TEST(LogiVectors, DecodeGivesBackEverySpecMessage) {
  for (const auto& v : kSpecFrames) {
    SCOPED_TRACE(v.frame);
    test::expect_decoded_vector(decode_frame(to_bytes(v.frame)), v);
  }
}

TEST(LogiVectors, ChecksumIsLowByteOfAsciiSum) {
  // 'L'+'O'+'G'+'I'+':'+'S'+'P'+':'+'0'+'5'+'0' = 0x2D7
  EXPECT_EQ(checksum("LOGI:SP:050"), 0xD7);
  EXPECT_EQ(checksum(""), 0x00);
}

TEST(LogiVectors, StatusRoundTripsWithEveryField) {
  Status s{.speed_percent = 50,
           .station = 2,
           .running = true,
           .mode = Mode::automatic,
           .manual = Direction::stop,
           .distance_cm = 123,
           .track_mask = 0b0110,
           .deviation = -3,
           .obstacle = false,
           .rpm = {120, 121, -119, 0}};
  const std::string text = encode_text(s);
  EXPECT_EQ(text.substr(0, text.size() - 4),
            "LOGI:STAT:SP:050,STA:002,RUN:1,MODE:AUTO,MAN:STOP,DIS:123,TRK:0110,DEV:-3,OBS:0,"
            "RPM:120:121:-119:0");
  const auto item = decode_frame(to_bytes(text));
  ASSERT_TRUE(std::holds_alternative<Frame<Message>>(item));
  EXPECT_EQ(std::get<Frame<Message>>(item).message, Message{s});
}

TEST(LogiVectors, FeedbackFrames) {
  EXPECT_EQ(payload_of(Feedback{Command::sp, true}), "FB:SP:1");
  EXPECT_EQ(payload_of(Feedback{Command::gs, false}), "FB:GS:0");
  EXPECT_EQ(payload_of(Feedback{Command::mv, false}), "FB:MV:0");
}

TEST(LogiVectors, EncodeRefusesValuesTheProtocolCannotCarry) {
  EXPECT_THROW(encode(SetSpeed{101}), std::invalid_argument);
  EXPECT_THROW(encode(SetStation{1000}), std::invalid_argument);
  Status s;
  s.extra = {{"BAT", "7,4"}};
  EXPECT_THROW(encode(s), std::invalid_argument);
}

// The STM32 parser (car_stm32f103vet6, Core/Bsp/protocol.c) takes one
// hand-over as one message: 10 bytes or more, '#' last, the checksum field
// after the last ':', the sum from index 0.
Item handover(std::string_view text) {
  return decode_handover(ByteView(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

TEST(LogiHandover, TheGuidesFramesAreTakenWhole) {
  for (const char* f : {"LOGI:MD:MAN:0C#", "LOGI:MD:AUTO:69#", "LOGI:SP:030:D5#", "LOGI:GS:001:CA#",
                        "LOGI:ST:RUN:3B#", "LOGI:MV:CCW:1F#", "LOGI:MV:STOP:88#"}) {
    EXPECT_TRUE(std::holds_alternative<Frame<Message>>(handover(f))) << f;
  }
  // The checksum field is found from the last ':': FB:SP:1 is one payload.
  const auto fb = handover("LOGI:FB:SP:1:35#");
  ASSERT_TRUE(std::holds_alternative<Frame<Message>>(fb));
  EXPECT_EQ(std::get<Frame<Message>>(fb).message, (Message{Feedback{Command::sp, true}}));
}

TEST(LogiHandover, WhatTheFirmwareRefuses) {
  struct Case {
    const char* text;
    ErrorKind kind;
    const char* detail;
  };
  const Case cases[] = {
      {"LOGI::65#", ErrorKind::bad_format, "a hand-over of 9 bytes; the firmware takes 10 or more"},
      {"LOGI:SP:050:D7#\r\n", ErrorKind::bad_format, "the hand-over ends with 0x0A, not '#'"},
      {"LOGI:SP:050:D7#LOGI:MD:MAN:0C#", ErrorKind::bad_checksum, "checksum 0C, computed"},
      {"xxLOGI:SP:050:D7#", ErrorKind::bad_format, "not a LOGI:...# frame"},
      {"LOGI:SP:050:D7", ErrorKind::bad_format, "not '#'"},
      {"LOGI:SPxx050xD7#", ErrorKind::bad_format, "no ':' before the checksum"},
  };
  for (const auto& c : cases) {
    const auto item = handover(c.text);
    ASSERT_TRUE(std::holds_alternative<DecodeError>(item)) << c.text;
    EXPECT_EQ(std::get<DecodeError>(item).kind, c.kind) << c.text;
    EXPECT_NE(std::get<DecodeError>(item).detail.find(c.detail), std::string::npos)
        << c.text << ": " << std::get<DecodeError>(item).detail;
  }
}

TEST(LogiHandover, ProfileNamesMapToDialects) {
  EXPECT_EQ(dialect_named(""), Dialect::guide);
  EXPECT_EQ(dialect_named("firmware"), Dialect::firmware);
  EXPECT_EQ(dialect_named("guide"), Dialect::guide);
  EXPECT_EQ(to_string(Dialect::guide), "guide");
  EXPECT_THROW(dialect_named("stream"), ProfileError);
}

}  // namespace
}  // namespace hil::protocol::logi
