#include <gtest/gtest.h>

#include "protocol/logi/codec.hpp"
#include "tests/protocol/decoder_test_support.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::logi {
namespace {

std::vector<Item> decode_all(std::string_view stream, DecoderOptions options = {}) {
  return test::decode_whole<Decoder, Item>(Decoder(options), to_bytes(stream));
}

using test::error_at;
using test::message_at;

TEST(LogiDecoder, StickyPacketsInOneReadGiveEveryFrame) {
  const auto items = decode_all("LOGI:FB:SP:1:35#LOGI:FB:MD:1:23#LOGI:FB:MV:0:34#");
  ASSERT_EQ(items.size(), 3u);
  EXPECT_EQ(test::messages_of(items),
            (std::vector<Message>{Feedback{Command::sp, true}, Feedback{Command::md, true},
                                  Feedback{Command::mv, false}}));
}

TEST(LogiDecoder, SplitPacketIsReassembled) {
  test::expect_reassembled<Decoder>({to_bytes("LOG"), to_bytes("I:SP:0"), to_bytes("50:D7#LOGI:")},
                                    std::nullopt, Message{SetSpeed{50}}, 5u);
}

TEST(LogiDecoder, GarbageBeforeHeaderIsReportedAndDiscarded) {
  test::expect_error_then_frame(decode_all("\r\nOK>LOGI:SP:050:D7#"), ErrorKind::garbage,
                                to_bytes("\r\nOK>"), Message{SetSpeed{50}});
}

TEST(LogiDecoder, BadChecksumIsDroppedWithRawTextAndStreamContinues) {
  const auto items = decode_all("LOGI:SP:050:D8#LOGI:SP:030:D5#");
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(error_at(items, 0).kind, ErrorKind::bad_checksum);
  EXPECT_EQ(to_string(error_at(items, 0).raw), "LOGI:SP:050:D8#");
  EXPECT_EQ(error_at(items, 0).context, "SP");
  EXPECT_NE(error_at(items, 0).detail.find("computed D7"), std::string::npos);
  EXPECT_EQ(message_at(items, 1), Message{SetSpeed{30}});
}

TEST(LogiDecoder, LowercaseChecksumIsADistinctViolation) {
  const auto strict = decode_all("LOGI:SP:050:d7#");
  ASSERT_EQ(strict.size(), 1u);
  EXPECT_EQ(error_at(strict, 0).kind, ErrorKind::lowercase_checksum);

  const auto lenient =
      decode_all("LOGI:SP:050:d7#", DecoderOptions{.accept_lowercase_checksum = true});
  ASSERT_EQ(lenient.size(), 1u);
  const auto& f = std::get<Frame<Message>>(lenient[0]);
  EXPECT_EQ(f.message, Message{SetSpeed{50}});
  EXPECT_EQ(f.tolerated, ErrorKind::lowercase_checksum);

  // A wrong value in lowercase is a checksum error, lenient or not.
  const auto wrong =
      decode_all("LOGI:SP:050:d8#", DecoderOptions{.accept_lowercase_checksum = true});
  EXPECT_EQ(error_at(wrong, 0).kind, ErrorKind::bad_checksum);
}

TEST(LogiDecoder, UnknownStatKeysAreKept) {
  const std::string payload =
      "STAT:SP:030,STA:001,RUN:0,MODE:MAN,MAN:CW,DIS:45,TRK:1001,DEV:0,OBS:1,RPM:1:2:3:4,BAT:7.4V,"
      "FW:v1:2";
  const auto items = decode_all(frame_text(payload));
  ASSERT_EQ(items.size(), 1u);
  const auto& s = std::get<Status>(std::get<Frame<Message>>(items[0]).message);
  EXPECT_EQ(s.mode, Mode::manual);
  EXPECT_EQ(s.manual, Direction::cw);
  EXPECT_EQ(s.track_mask, 0b1001);
  EXPECT_TRUE(s.obstacle);
  ASSERT_EQ(s.extra.size(), 2u);
  EXPECT_EQ(s.extra[0], (std::pair<std::string, std::string>{"BAT", "7.4V"}));
  EXPECT_EQ(s.extra[1], (std::pair<std::string, std::string>{"FW", "v1:2"}));
}

TEST(LogiDecoder, StatFieldsInAnotherOrderStillDecode) {
  const auto items = decode_all(frame_text(
      "STAT:RPM:0:0:0:0,OBS:0,DEV:5,TRK:0000,DIS:300,MAN:STOP,MODE:AUTO,RUN:0,STA:2,SP:7"));
  const auto& s = std::get<Status>(std::get<Frame<Message>>(items.at(0)).message);
  EXPECT_EQ(s.speed_percent, 7);
  EXPECT_EQ(s.station, 2);
  EXPECT_EQ(s.deviation, 5);
}

TEST(LogiDecoder, StatMissingOrRepeatedKeyNamesIt) {
  const auto missing = decode_all(frame_text("STAT:SP:030,STA:001,RUN:0,MODE:MAN,MAN:CW"));
  EXPECT_EQ(error_at(missing, 0).kind, ErrorKind::bad_format);
  EXPECT_NE(error_at(missing, 0).detail.find("lacks key DIS"), std::string::npos);
  const auto twice = decode_all(frame_text("STAT:SP:030,SP:030"));
  EXPECT_NE(error_at(twice, 0).detail.find("SP repeated"), std::string::npos);
  const auto bad = decode_all(frame_text(
      "STAT:SP:030,STA:001,RUN:2,MODE:MAN,MAN:CW,DIS:45,TRK:1001,DEV:0,OBS:1,RPM:1:2:3:4"));
  EXPECT_NE(error_at(bad, 0).detail.find("RUN:2"), std::string::npos);
}

TEST(LogiDecoder, MalformedCommandsCarryTheirCommandCode) {
  struct Case {
    const char* payload;
    ErrorKind kind;
    const char* context;
  };
  for (const Case& c :
       {Case{"SP:50", ErrorKind::bad_format, "SP"}, Case{"SP:101", ErrorKind::bad_value, "SP"},
        Case{"SP:abc", ErrorKind::bad_format, "SP"}, Case{"GS:1", ErrorKind::bad_format, "GS"},
        Case{"ST:GO", ErrorKind::bad_format, "ST"}, Case{"MD:MANUAL", ErrorKind::bad_format, "MD"},
        Case{"MV:UP", ErrorKind::bad_format, "MV"}, Case{"FB:XX:1", ErrorKind::bad_format, "FB"},
        Case{"FB:SP:2", ErrorKind::bad_format, "FB"}, Case{"ZZ:1", ErrorKind::unknown_code, "ZZ"},
        Case{"PING", ErrorKind::bad_format, "PING"}}) {
    const auto items = decode_all(frame_text(c.payload));
    ASSERT_EQ(items.size(), 1u) << c.payload;
    EXPECT_EQ(error_at(items, 0).kind, c.kind) << c.payload;
    EXPECT_EQ(error_at(items, 0).context, c.context) << c.payload;
  }
}

TEST(LogiDecoder, GarbageThatLooksLikeAHeaderDoesNotSwallowTheNextFrame) {
  test::expect_error_then_frame(decode_all("LOGI:SP:0LOGI:SP:050:D7#"), ErrorKind::bad_format,
                                to_bytes("LOGI:SP:0"), Message{SetSpeed{50}});
}

TEST(LogiDecoder, OversizedFrameIsBoundedAndReported) {
  std::string stream = "LOGI:" + std::string(400, 'A') + "LOGI:SP:050:D7#";
  const auto out = test::decode_bytewise_within<Decoder, Item>(Decoder{}, to_bytes(stream),
                                                               kDefaultMaxFrameBytes);
  EXPECT_EQ(test::count_errors(out, ErrorKind::oversized), 1u);
  EXPECT_EQ(test::messages_of(out), std::vector<Message>{SetSpeed{50}});
}

TEST(LogiDecoder, NonAsciiPayloadIsBadFormat) {
  std::string payload = "MV:FWD";
  payload[3] = static_cast<char>(0xC6);
  auto frame = frame_text(payload);
  const auto items = decode_all(frame);
  EXPECT_EQ(error_at(items, 0).kind, ErrorKind::bad_format);
}

TEST(LogiDecoder, StreamEndingInsideAFrameIsTruncated) {
  const auto items = decode_all("LOGI:SP:050:D7#LOGI:SP:0");
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(error_at(items, 1).kind, ErrorKind::truncated);
}

}  // namespace
}  // namespace hil::protocol::logi
