#include <gtest/gtest.h>

#include "protocol/leka/codec.hpp"
#include "tests/protocol/decoder_test_support.hpp"
#include "tests/support/hex.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::leka {
namespace {

using test::hex;

const Bytes kInfo = hex("2A 2B 2C 2D 01 70 70");
const Bytes kBeltRed = hex("2A 2B 2C 2D 05 15 00 FF 00 00 41");

std::vector<Item> decode_all(ByteView stream, DecoderOptions options = {}) {
  return test::decode_whole<Decoder, Item>(Decoder(options), stream);
}

using test::error_at;
using test::frame_at;

Bytes cat(std::initializer_list<Bytes> parts) {
  return test::concat(parts);
}

const CommandGroup kInfoGroup{{Info{}}};

DecoderOptions with_bound(std::size_t max_frame_bytes) {
  DecoderOptions o;
  o.max_frame_bytes = max_frame_bytes;
  return o;
}

DecoderOptions tolerant() {
  DecoderOptions o;
  o.accept_out_of_range = true;
  return o;
}
const CommandGroup kBeltRedGroup{{BeltSingle{0, Rgb{255, 0, 0}}}};

TEST(LekaDecoder, StickyPacketsInOneReadGiveEveryFrame) {
  const auto items = decode_all(cat({kBeltRed, kInfo, kBeltRed}));
  ASSERT_EQ(items.size(), 3u);
  EXPECT_EQ(test::messages_of(items),
            (std::vector<Message>{kBeltRedGroup, kInfoGroup, kBeltRedGroup}));
  EXPECT_EQ(frame_at(items, 1).raw, kInfo);
}

TEST(LekaDecoder, SplitPacketIsReassembled) {
  // The last read leaves a start-sequence prefix waiting for more.
  test::expect_reassembled<Decoder>(
      {hex("2A 2B"), hex("2C 2D 05 15"), hex("00 FF 00"), hex("00 41 2A 2B")}, 9u,
      Message{kBeltRedGroup}, 2u);
}

TEST(LekaDecoder, GarbageBeforeAFrameIsReportedAndDiscarded) {
  test::expect_error_then_frame(decode_all(cat({hex("00 2A 2B FF 2C"), kInfo})), ErrorKind::garbage,
                                hex("00 2A 2B FF 2C"), Message{kInfoGroup});
}

TEST(LekaDecoder, LongGarbageComesOutInBoundedChunks) {
  const Bytes noise(300, 0x55);
  const auto items = decode_all(cat({noise, kInfo}));
  ASSERT_EQ(items.size(), 4u);
  EXPECT_EQ(error_at(items, 0).raw.size(), 128u);
  EXPECT_EQ(error_at(items, 1).raw.size(), 128u);
  EXPECT_EQ(error_at(items, 2).raw.size(), 44u);
  EXPECT_EQ(frame_at(items, 3).message, kInfoGroup);
}

TEST(LekaDecoder, BadChecksumIsReportedWithItsBytesAndTheStreamContinues) {
  Bytes bad = kBeltRed;
  bad.back() = 0x42;
  const auto items = decode_all(cat({bad, kInfo}));
  test::expect_error_then_frame(items, ErrorKind::bad_checksum, bad, Message{kInfoGroup});
  test::expect_error_at(
      items, 0,
      {ErrorKind::bad_checksum, "led.belt.single", "0x42 at frame byte 10 does not match 0x41"});
}

TEST(LekaDecoder, HeaderLikeGarbageDoesNotSwallowTheNextFrame) {
  // A start sequence and a length of 14 in garbage: the candidate runs over
  // the real frame, fails its checksum, and is cut at the real start.
  const Bytes garbage = hex("2A 2B 2C 2D 0E 99");
  Bytes stream = cat({garbage, kBeltRed, kInfo});
  const auto items = decode_all(stream);
  ASSERT_EQ(items.size(), 3u);
  EXPECT_EQ(error_at(items, 0).kind, ErrorKind::bad_checksum);
  EXPECT_EQ(error_at(items, 0).raw, garbage);
  EXPECT_NE(error_at(items, 0).detail.find("reported up to frame byte 6"), std::string::npos);
  EXPECT_EQ(frame_at(items, 1).message, kBeltRedGroup);
  EXPECT_EQ(frame_at(items, 2).message, kInfoGroup);
}

TEST(LekaDecoder, StartSequenceSplitAtTheEndOfAFailedCandidateIsKept) {
  // The candidate (length 3) ends in the middle of the next start sequence.
  const Bytes stream = cat({hex("2A 2B 2C 2D 03 01 2A 2B"), hex("2C 2D 01 70 70")});
  for (const std::size_t piece : {1u, 2u, 3u, 100u}) {
    const auto items = test::decode_chunked<Decoder, Item>(Decoder{}, stream, {piece});
    ASSERT_EQ(items.size(), 2u) << piece;
    EXPECT_EQ(error_at(items, 0).kind, ErrorKind::bad_checksum);
    EXPECT_EQ(error_at(items, 0).raw, hex("2A 2B 2C 2D 03 01"));
    EXPECT_EQ(frame_at(items, 1).message, kInfoGroup);
  }
}

TEST(LekaDecoder, StartSequenceInsideAValidGroupIsJustData) {
  // Colour bytes 2A 2B 2C after a 2D id byte are not a resynchronisation point.
  const CommandGroup g{{EarAll{Rgb{0x2A, 0x2B, 0x2C}}, BeltAll{Rgb{0x2A, 0x2B, 0x2C}}}};
  const auto items = decode_all(encode(g));
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(frame_at(items, 0).message, g);
}

TEST(LekaDecoder, ZeroLengthIsBadFormatAndOnlyTheHeaderIsDropped) {
  test::expect_error_then_frame(decode_all(cat({hex("2A 2B 2C 2D 00"), kInfo})),
                                ErrorKind::bad_format, hex("2A 2B 2C 2D 00"), Message{kInfoGroup});
}

TEST(LekaDecoder, LengthOverTheRobotBufferIsOversizedAndDecodingResumesAfterIt) {
  const auto items = decode_all(cat({hex("2A 2B 2C 2D 7B"), kInfo}));  // 123 > 122
  test::expect_error_then_frame(items, ErrorKind::oversized, hex("2A 2B 2C 2D 7B"),
                                Message{kInfoGroup});
  test::expect_error_at(items, 0, {ErrorKind::oversized, std::nullopt, "123-byte command group"});

  // 122 is the largest group the robot takes.
  CommandGroup g;
  for (int i = 0; i < 61; ++i)
    g.commands.push_back(Motivator{0x51});
  const auto full = decode_all(encode(g));
  ASSERT_EQ(full.size(), 1u);
  EXPECT_EQ(frame_at(full, 0).message, g);
}

TEST(LekaDecoder, LargerBoundIsConfigurable) {
  const Bytes frame = frame_group(Bytes(200, 0x70));
  EXPECT_EQ(error_at(decode_all(frame), 0).kind, ErrorKind::oversized);
  const auto items = decode_all(frame, with_bound(261));
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(frame_at(items, 0).message.commands.size(), 200u);
  EXPECT_THROW(Decoder(with_bound(6)), std::invalid_argument);
  EXPECT_THROW(Decoder(with_bound(262)), std::invalid_argument);
}

// Expects the frame around `group` to decode to one error over the whole frame.
void expect_one_error_over_the_frame(std::string_view group, const test::ExpectedError& want) {
  const Bytes frame = frame_group(hex(group));
  const auto items = decode_all(frame);
  ASSERT_EQ(items.size(), 1u);
  test::expect_error_at(items, 0, want);
  EXPECT_EQ(error_at(items, 0).raw, frame);
}

TEST(LekaDecoder, UnknownCommandIdIsUnknownCodeWithTheWholeFrame) {
  expect_one_error_over_the_frame(
      "70 99 01", {ErrorKind::unknown_code, "0x99",
                   "unknown command id 0x99 at group byte 1, frame byte 6 (command 2)"});
}

TEST(LekaDecoder, CommandCutShortByTheGroupEndIsBadFormat) {
  expect_one_error_over_the_frame("70 15 03 FF",
                                  {ErrorKind::bad_format, "led.belt.single",
                                   "needs 4 data byte(s), the group has only 2 left"});
}

TEST(LekaDecoder, ValuesOutOfRangeAreBadValueUnlessTolerated) {
  struct Case {
    const char* group;
    const char* context;
    const char* says;
  };
  for (const Case& c :
       {Case{"12 02 00 00 00", "led.ear.single", "ear LED id 0x02"},
        Case{"15 14 00 00 00", "led.belt.single", "belt LED id 0x14 outside 0x00..0x13"},
        Case{"14 00 14 01 02 03", "led.belt.range", "last belt LED id 0x14"},
        Case{"14 05 04 01 02 03", "led.belt.range", "0x05 is after last 0x04"},
        Case{"21 02 10", "motor.all", "direction 0x02"},
        Case{"22 00 10 03 10", "motor.duo", "right spin 0x03"},
        Case{"23 FF 10", "motor.left", "spin 0xFF"}, Case{"24 02 10", "motor.right", "spin 0x02"},
        Case{"50 50", "motivator", "motivator id 0x50 outside 0x51..0x55"},
        Case{"40 50", "guidance", "guidance id 0x50 outside 0x41..0x4F"}}) {
    SCOPED_TRACE(c.group);
    expect_one_error_over_the_frame(c.group, {ErrorKind::bad_value, c.context, c.says});

    const auto lenient = decode_all(frame_group(hex(c.group)), tolerant());
    ASSERT_EQ(lenient.size(), 1u);
    const auto& f = frame_at(lenient, 0);
    EXPECT_EQ(f.tolerated, ErrorKind::bad_value) << c.group;
    EXPECT_EQ(group_bytes(f.message), hex(c.group));
  }
}

TEST(LekaDecoder, BadValueNamesTheCommandItIsIn) {
  const auto items = decode_all(frame_group(hex("70 12 01 00 00 00 12 05 00 00 00")));
  EXPECT_NE(error_at(items, 0).detail.find("command 3, group byte 6, frame byte 11"),
            std::string::npos)
      << error_at(items, 0).detail;
}

TEST(LekaDecoder, BeltLimitFollowsTheTableWhenAsked) {
  const Bytes frame = frame_group(hex("15 19 00 00 00"));
  EXPECT_EQ(error_at(decode_all(frame), 0).kind, ErrorKind::bad_value);
  DecoderOptions table;
  table.limits.max_belt_led_id = 0x19;
  const auto items = decode_all(frame, table);
  EXPECT_EQ(frame_at(items, 0).message, (CommandGroup{{BeltSingle{0x19, Rgb{}}}}));
  EXPECT_FALSE(frame_at(items, 0).tolerated);
}

TEST(LekaDecoder, StreamEndingInsideAFrameIsTruncated) {
  const auto items = decode_all(cat({kInfo, hex("2A 2B 2C 2D 05 15 00")}));
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(error_at(items, 1).kind, ErrorKind::truncated);
  EXPECT_EQ(error_at(items, 1).raw, hex("2A 2B 2C 2D 05 15 00"));
  EXPECT_EQ(error_at(items, 1).context, "led.belt.single");

  const auto header_only = decode_all(hex("2A 2B 2C 2D"));
  ASSERT_EQ(header_only.size(), 1u);
  EXPECT_EQ(error_at(header_only, 0).kind, ErrorKind::truncated);
}

TEST(LekaDecoder, FrameInsideATruncatedCandidateStillDecodes) {
  // Garbage announcing 100 bytes, then a real frame, then the stream ends.
  test::expect_error_then_frame(decode_all(cat({hex("2A 2B 2C 2D 64 00"), kInfo})),
                                ErrorKind::truncated, hex("2A 2B 2C 2D 64 00"),
                                Message{kInfoGroup});
}

TEST(LekaDecoder, PartialStartSequenceAtTheEndIsGarbage) {
  const auto items = decode_all(cat({kInfo, hex("2A 2B 2C")}));
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(error_at(items, 1).kind, ErrorKind::garbage);
  EXPECT_EQ(error_at(items, 1).raw, hex("2A 2B 2C"));
}

TEST(LekaDecoder, BufferNeverExceedsTheFrameBound) {
  Bytes stream = cat({hex("2A 2B 2C 2D 7A"), Bytes(121, 0x2A), Bytes(500, 0x11), kInfo});
  Decoder d;
  std::vector<Item> out;
  for (const std::uint8_t b : stream) {
    d.feed(ByteView(&b, 1), out);
    ASSERT_LE(d.buffered(), kMaxFrameBytes);
  }
  d.finish(out);
  EXPECT_EQ(d.buffered(), 0u);
  EXPECT_EQ(test::messages_of(out), std::vector<Message>{kInfoGroup});
}

TEST(LekaDecoder, FinishResetsForANewStream) {
  Decoder d;
  std::vector<Item> out;
  d.feed(hex("2A 2B 2C 2D 05"), out);
  d.finish(out);
  out.clear();
  d.feed(kInfo, out);
  d.finish(out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(frame_at(out, 0).message, kInfoGroup);
}

TEST(LekaDecoder, DecodeFrameChecksOneCompleteFrame) {
  EXPECT_EQ(std::get<DecodeError>(decode_frame(hex("2A 2B 2C 2D 02 70 70"))).kind,
            ErrorKind::bad_format);
  EXPECT_EQ(std::get<DecodeError>(decode_frame(hex("2A 2B 2C 2E 01 70 70"))).kind,
            ErrorKind::bad_format);
  EXPECT_EQ(std::get<DecodeError>(decode_frame(hex("2A 2B 2C 2D 01 70 71"))).kind,
            ErrorKind::bad_checksum);
  EXPECT_EQ(std::get<DecodeError>(decode_frame(frame_group(Bytes(123, 0x70)))).kind,
            ErrorKind::oversized);
}

}  // namespace
}  // namespace hil::protocol::leka
