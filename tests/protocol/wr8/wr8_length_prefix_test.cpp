// The length byte the real WR8 programs put before every packet. The
// vectors are the bytes smart_vehicle_gui sends (v2019 = 8d80e92, HEAD =
// 431e8d4): AUTH from both GUIs, and the vehicle's fixed AUTH-REPLY.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <stdexcept>

#include "protocol/wr8/length_prefix.hpp"
#include "tests/protocol/decoder_test_support.hpp"
#include "tests/support/hex.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::wr8 {
namespace {

using test::hex;

// "konnichiwa"
constexpr std::string_view kKonnichiwa = "6B 6F 6E 6E 69 63 68 69 77 61";

Bytes auth_2019() { return hex("0B 01 " + std::string(kKonnichiwa)); }
Bytes auth_head() { return hex("0C 01 " + std::string(kKonnichiwa) + " 00"); }
Bytes auth_reply() { return hex("04 02 01 02 03"); }

std::vector<PrefixedItem> split_whole(ByteView stream) {
  return test::decode_whole<LengthPrefixSplitter, PrefixedItem>(LengthPrefixSplitter{}, stream);
}

using test::error_at;
using test::frame_at;

TEST(Wr8LengthPrefix, TheGuisAuthPacketsAreOnePacketEach) {
  const auto v2019 = split_whole(auth_2019());
  ASSERT_EQ(v2019.size(), 1u);
  EXPECT_EQ(frame_at(v2019, 0).message, hex("01 " + std::string(kKonnichiwa)));
  EXPECT_EQ(frame_at(v2019, 0).raw, auth_2019());

  const auto head = split_whole(auth_head());
  ASSERT_EQ(head.size(), 1u);
  EXPECT_EQ(frame_at(head, 0).message.size(), 12u);  // code, ten letters, the NUL
  EXPECT_EQ(frame_at(head, 0).message.back(), 0x00);
}

TEST(Wr8LengthPrefix, PrefixingAPacketGivesTheBytesTheRealProgramsSend) {
  EXPECT_EQ(prefix_length(hex("01 " + std::string(kKonnichiwa))), auth_2019());
  EXPECT_EQ(prefix_length(hex("02 01 02 03")), auth_reply());
}

TEST(Wr8LengthPrefix, CoalescedPacketsComeOutOneByOne) {
  Bytes stream = auth_reply();
  const Bytes set_request = hex("01 06");
  stream.insert(stream.end(), set_request.begin(), set_request.end());
  const auto items = split_whole(stream);
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(frame_at(items, 0).message, hex("02 01 02 03"));
  EXPECT_EQ(frame_at(items, 1).message, hex("06"));
}

TEST(Wr8LengthPrefix, APacketSplitAcrossReadsWaitsForItsLastByte) {
  LengthPrefixSplitter splitter;
  std::vector<PrefixedItem> out;
  const Bytes stream = auth_2019();
  splitter.feed(ByteView(stream).first(1), out);
  splitter.feed(ByteView(stream).subspan(1, 5), out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(splitter.buffered(), 6u);
  splitter.feed(ByteView(stream).subspan(6), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(frame_at(out, 0).raw, stream);
  EXPECT_EQ(splitter.buffered(), 0u);
}

TEST(Wr8LengthPrefix, ALengthOf128OrMoreIsATypedErrorOfThatByte) {
  // 0x80 declares 128 bytes; the real receiver reads it as -128.
  const auto items = split_whole(hex("80 04 02 01 02 03"));
  test::expect_error_then_frame(items, ErrorKind::oversized, hex("80"), hex("02 01 02 03"));
  EXPECT_THAT(error_at(items, 0).detail, testing::HasSubstr("0x80"));

  EXPECT_EQ(error_at(split_whole(hex("FF")), 0).kind, ErrorKind::oversized);
}

TEST(Wr8LengthPrefix, ALengthOfZeroFramesNothing) {
  const auto items = split_whole(hex("00 04 02 01 02 03"));
  test::expect_error_then_frame(items, ErrorKind::bad_format, hex("00"), hex("02 01 02 03"));
  EXPECT_EQ(frame_at(items, 1).raw, auth_reply());
}

TEST(Wr8LengthPrefix, AStreamEndingInsideAPacketIsTruncatedWithItsBytes) {
  const auto items = split_whole(hex("04 02 01"));
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(error_at(items, 0).kind, ErrorKind::truncated);
  EXPECT_EQ(error_at(items, 0).raw, hex("04 02 01"));
  EXPECT_THAT(error_at(items, 0).detail, testing::HasSubstr("2 of 4"));
}

TEST(Wr8LengthPrefix, PrefixingRefusesWhatNoReceiverCouldReadBack) {
  EXPECT_THROW(prefix_length(Bytes{}), std::invalid_argument);
  EXPECT_NO_THROW(prefix_length(Bytes(kLongestPrefixedPacket, 0x06)));
  EXPECT_THROW(prefix_length(Bytes(kLongestPrefixedPacket + 1, 0x06)), std::invalid_argument);
}

RC_GTEST_PROP(Wr8LengthPrefixProperties, PrefixedPacketsComeBackWhateverTheChunking, ()) {
  const auto packets = *rc::gen::container<std::vector<Bytes>>(rc::gen::mapcat(
      rc::gen::inRange<std::size_t>(1, kLongestPrefixedPacket + 1), [](std::size_t n) {
        return rc::gen::container<Bytes>(n, rc::gen::arbitrary<std::uint8_t>());
      }));
  std::vector<Bytes> parts;
  for (const auto& p : packets)
    parts.push_back(prefix_length(p));
  const Bytes stream = test::concat(parts);
  const auto chunked = test::decode_chunked<LengthPrefixSplitter, PrefixedItem>(
      LengthPrefixSplitter{}, stream, *test::gen_pieces());
  RC_ASSERT(test::messages_of(chunked) == packets);
  RC_ASSERT(chunked.size() == packets.size());
}

RC_GTEST_PROP(Wr8LengthPrefixProperties, AnyStreamIsCutTheSameWayAndEveryByteIsKept, ()) {
  const auto stream = *rc::gen::container<Bytes>(rc::gen::arbitrary<std::uint8_t>());
  const auto whole = split_whole(stream);
  const auto chunked = test::decode_chunked<LengthPrefixSplitter, PrefixedItem>(
      LengthPrefixSplitter{}, stream, *test::gen_pieces());
  RC_ASSERT(chunked == whole);
  RC_ASSERT(test::raw_of_all(whole) == stream);
}

}  // namespace
}  // namespace hil::protocol::wr8
