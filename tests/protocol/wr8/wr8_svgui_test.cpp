// The packets of smart_vehicle_gui's vehicle and GUI, v2019 (8d80e92) and
// head (431e8d4), byte for byte: each vector is laid out as the real
// program writes it (QDataStream big-endian with 4-byte codes and 8-byte
// doubles; v2019's TASK and SETTINGS little-endian by hand).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>

#include "protocol/common/car_profile.hpp"
#include "protocol/wr8/length_prefix.hpp"
#include "protocol/wr8/svgui.hpp"
#include "tests/support/hex.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::wr8::svgui {
namespace {

using test::hex;

// 10:00:00 local time, in milliseconds since midnight: 36,000,000 = 0x02255100.
constexpr std::uint32_t kTenOClock = 36'000'000;

// v2019 DATA: WAIT, encoder 100, steering 1.5, batteries 80 and 60.
constexpr std::string_view kData2019 =
    "06 03 02 25 51 00"
    " 00 00 00 01 00 00 00 64"
    " 00 00 00 02 3F F8 00 00 00 00 00 00"
    " 00 00 00 03 00 00 00 50"
    " 00 00 00 04 00 00 00 3C";

// head HIGH-FREQ DATA: encoder 2, steering 0, x 1.5, y 2.5, angle 90.
constexpr std::string_view kHighFreq =
    "09 02 25 51 00"
    " 00 00 00 01 40 00 00 00 00 00 00 00"
    " 00 00 00 02 00 00 00 00 00 00 00 00"
    " 00 00 00 03 3F F8 00 00 00 00 00 00"
    " 00 00 00 04 40 04 00 00 00 00 00 00"
    " 00 00 00 05 40 56 80 00 00 00 00 00";

// head LOW-FREQ DATA: WAIT, batteries 50 and 75, temperature 40.
constexpr std::string_view kLowFreq =
    "08 03 02 25 51 00"
    " 00 00 00 01 00 00 00 32"
    " 00 00 00 02 00 00 00 4B"
    " 00 00 00 03 40 44 00 00 00 00 00 00";

// head MAP of the real test vehicle: 8 wide, 6 rows.
constexpr std::string_view kMap =
    "07 08 06 00 00 00 06"
    " 00 00 00 08 01 01 01 01 01 01 01 01"
    " 00 00 00 08 01 00 00 00 00 00 00 01"
    " 00 00 00 08 01 00 01 01 01 01 00 01"
    " 00 00 00 08 01 00 01 00 00 01 00 01"
    " 00 00 00 08 01 00 01 00 00 00 00 01"
    " 00 00 00 08 01 00 01 01 01 01 01 01";

Map test_vehicle_map() {
  return Map{8, 6,
             {{1, 1, 1, 1, 1, 1, 1, 1},
              {1, 0, 0, 0, 0, 0, 0, 1},
              {1, 0, 1, 1, 1, 1, 0, 1},
              {1, 0, 1, 0, 0, 1, 0, 1},
              {1, 0, 1, 0, 0, 0, 0, 1},
              {1, 0, 1, 1, 1, 1, 1, 1}}};
}

Message decoded(std::string_view vector, Version version) {
  const Item item = decode_packet(hex(vector), version);
  if (const auto* e = std::get_if<DecodeError>(&item)) {
    ADD_FAILURE() << "decode failed: " << e->detail;
    return SetRequest{};
  }
  return std::get<Frame<Message>>(item).message;
}

const DecodeError& error_of(const Item& item) { return std::get<DecodeError>(item); }

TEST(Wr8Svgui, EachRealProgramProfileNamesItsVersion) {
  EXPECT_EQ(version_of_profile("svgui-2019"), Version::v2019);
  EXPECT_EQ(version_of_profile("svgui-head"), Version::head);
  EXPECT_EQ(version_of_profile("document"), std::nullopt);
  EXPECT_EQ(version_of_profile(""), std::nullopt);  // the default: the document
  EXPECT_THROW(version_of_profile("svgui"), ProfileError);
  EXPECT_EQ(profile_of(Version::v2019), "svgui-2019");
  EXPECT_EQ(profile_of(Version::head), "svgui-head");
}

TEST(Wr8Svgui, AuthIsTheTextAfterTheCodeInBothVersions) {
  const Auth v2019{to_bytes("konnichiwa")};
  Bytes head_text = to_bytes("konnichiwa");
  head_text.push_back(0);
  const Auth head{head_text};
  EXPECT_EQ(encode_prefixed(v2019, Version::v2019), hex("0B 01 6B 6F 6E 6E 69 63 68 69 77 61"));
  EXPECT_EQ(encode_prefixed(head, Version::head), hex("0C 01 6B 6F 6E 6E 69 63 68 69 77 61 00"));
  EXPECT_EQ(decoded("01 6B 6F 6E 6E 69 63 68 69 77 61 00", Version::head), Message{head});
}

TEST(Wr8Svgui, TheFixedAuthReplyIsDeviceOneIdTwoWait) {
  EXPECT_EQ(encode_prefixed(kProgramAuthReply, Version::head), hex("04 02 01 02 03"));
  EXPECT_EQ(decoded("02 01 02 03", Version::v2019), (Message{AuthReply{1, 2, State::wait}}));
}

TEST(Wr8Svgui, V2019DataIs42BytesBigEndianWithFourByteCodesAndADoubleSteering) {
  const Data data{State::wait, kTenOClock, 100, 1.5, 80, 60};
  EXPECT_EQ(encode(data, Version::v2019), hex(kData2019));
  EXPECT_EQ(hex(kData2019).size(), 42u);
  EXPECT_EQ(decoded(kData2019, Version::v2019), Message{data});
}

TEST(Wr8Svgui, HeadHighFrequencyDataIs65Bytes) {
  const HighFreqData data{kTenOClock, 2, 0, 1.5, 2.5, 90};
  EXPECT_EQ(encode(data, Version::head), hex(kHighFreq));
  EXPECT_EQ(hex(kHighFreq).size(), 65u);
  EXPECT_EQ(decoded(kHighFreq, Version::head), Message{data});
}

TEST(Wr8Svgui, HeadLowFrequencyDataIs34Bytes) {
  const LowFreqData data{State::wait, kTenOClock, 50, 75, 40};
  EXPECT_EQ(encode(data, Version::head), hex(kLowFreq));
  EXPECT_EQ(hex(kLowFreq).size(), 34u);
  EXPECT_EQ(decoded(kLowFreq, Version::head), Message{data});
}

TEST(Wr8Svgui, HeadMapOfEightBySixIs79Bytes) {
  EXPECT_EQ(encode(test_vehicle_map(), Version::head), hex(kMap));
  EXPECT_EQ(hex(kMap).size(), 79u);
  EXPECT_EQ(decoded(kMap, Version::head), (Message{test_vehicle_map()}));
}

TEST(Wr8Svgui, V2019TaskCountsParametersAndWritesThemLittleEndian) {
  const Task forward{1, 1, {100}};
  EXPECT_EQ(encode_prefixed(forward, Version::v2019), hex("08 03 01 01 01 64 00 00 00"));
  EXPECT_EQ(decoded("03 07 02 01 E2 FF FF FF", Version::v2019), (Message{Task{7, 2, {-30}}}));
  EXPECT_EQ(decoded("03 02 03 00", Version::v2019), (Message{Task{2, 3, {}}}));
}

TEST(Wr8Svgui, V2019SettingsAreFourLittleEndianIntsWithoutTypeBytes) {
  const Settings s{5, {2, 1, 3, 90}};
  const Bytes packet = encode(s, Version::v2019);
  EXPECT_EQ(packet, hex("04 05 02 00 00 00 01 00 00 00 03 00 00 00 5A 00 00 00"));
  EXPECT_EQ(packet.size(), 18u);
  EXPECT_EQ(decoded("04 05 02 00 00 00 01 00 00 00 03 00 00 00 5A 00 00 00", Version::v2019),
            Message{s});
}

TEST(Wr8Svgui, HeadSetIsTwelveBigEndianDoubles) {
  Set s;
  s.values[0] = 1.5;   // steering p
  s.values[11] = 2.5;  // backward integral limit
  const Bytes packet = encode(s, Version::head);
  ASSERT_EQ(packet.size(), 97u);
  EXPECT_EQ(Bytes(packet.begin(), packet.begin() + 9), hex("04 3F F8 00 00 00 00 00 00"));
  EXPECT_EQ(Bytes(packet.end() - 8, packet.end()), hex("40 04 00 00 00 00 00 00"));
  EXPECT_EQ(decoded(to_hex(packet), Version::head), Message{s});
}

TEST(Wr8Svgui, AnswerCarriesACoiInV2019Only) {
  EXPECT_EQ(encode(Answer{4, 2}, Version::v2019), hex("05 04 02"));
  EXPECT_EQ(encode(Answer{std::nullopt, 1}, Version::head), hex("05 01"));
  EXPECT_THROW(encode(Answer{std::nullopt, 1}, Version::v2019), std::invalid_argument);
  EXPECT_THROW(encode(Answer{4, 2}, Version::head), std::invalid_argument);
}

TEST(Wr8Svgui, HeadSetRequestAndControl) {
  EXPECT_EQ(encode_prefixed(SetRequest{}, Version::head), hex("01 06"));
  const Control c{0.5, -1.0};
  EXPECT_EQ(encode(c, Version::head),
            hex("0A 00 00 00 01 3F E0 00 00 00 00 00 00 00 00 00 02 BF F0 00 00 00 00 00 00"));
  EXPECT_EQ(decoded("0A 00 00 00 01 3F E0 00 00 00 00 00 00 00 00 00 02 BF F0 00 00 00 00 00 00",
                    Version::head),
            Message{c});
}

TEST(Wr8Svgui, CodeSixIsDataInV2019AndSetRequestInHead) {
  EXPECT_EQ(decoded("06", Version::head), Message{SetRequest{}});
  EXPECT_EQ(error_of(decode_packet(hex("06"), Version::v2019)).kind, ErrorKind::bad_format);
}

TEST(Wr8Svgui, AVersionRefusesThePacketsOfTheOther) {
  EXPECT_THROW(encode(Task{1, 1, {100}}, Version::head), std::invalid_argument);
  EXPECT_THROW(encode(Control{}, Version::v2019), std::invalid_argument);
  const auto task_in_head = decode_packet(hex("03 01 01 01 64 00 00 00"), Version::head);
  EXPECT_EQ(error_of(task_in_head).kind, ErrorKind::unknown_code);
  EXPECT_EQ(error_of(decode_packet(hex(kHighFreq), Version::v2019)).kind, ErrorKind::unknown_code);
}

TEST(Wr8Svgui, ShortLongAndOddPacketsAreTypedErrorsWithTheirBytes) {
  Bytes cut = hex(kData2019);
  cut.pop_back();
  const auto short_data = decode_packet(cut, Version::v2019);
  EXPECT_EQ(error_of(short_data).kind, ErrorKind::bad_format);
  EXPECT_EQ(error_of(short_data).raw, cut);
  EXPECT_THAT(error_of(short_data).detail, testing::HasSubstr("cut short"));

  const auto long_reply = decode_packet(hex("02 01 02 03 00"), Version::head);
  EXPECT_THAT(error_of(long_reply).detail, testing::HasSubstr("1 bytes after its last field"));

  Bytes wrong_code = hex(kHighFreq);
  wrong_code[8] = 0x07;  // the encoder's code
  EXPECT_THAT(error_of(decode_packet(wrong_code, Version::head)).detail,
              testing::HasSubstr("data code at byte 5 is 7, expected 1"));

  const auto bad_state = decode_packet(hex("02 01 02 07"), Version::head);
  EXPECT_EQ(error_of(bad_state).kind, ErrorKind::bad_value);
  EXPECT_EQ(error_of(decode_packet(Bytes{}, Version::head)).kind, ErrorKind::bad_format);
}

TEST(Wr8Svgui, AMapWhoseCountsOverrunThePacketIsCutShortNotAllocated) {
  const auto huge = decode_packet(hex("07 08 06 FF FF FF FF 00 00 00 08 01"), Version::head);
  EXPECT_EQ(error_of(huge).kind, ErrorKind::bad_format);
}

TEST(Wr8Svgui, EveryVectorSurvivesTheLengthPrefixAndBack) {
  const std::vector<std::pair<Message, Version>> all = {
      {Data{State::wait, kTenOClock, 100, 1.5, 80, 60}, Version::v2019},
      {HighFreqData{kTenOClock, 2, 0, 1.5, 2.5, 90}, Version::head},
      {LowFreqData{State::wait, kTenOClock, 50, 75, 40}, Version::head},
      {test_vehicle_map(), Version::head},
      {Task{1, 1, {100}}, Version::v2019},
      {Set{}, Version::head},
  };
  for (const auto& [message, version] : all) {
    LengthPrefixSplitter splitter;
    std::vector<PrefixedItem> out;
    splitter.feed(encode_prefixed(message, version), out);
    ASSERT_EQ(out.size(), 1u) << describe(message);
    const auto& packet = std::get<Frame<Bytes>>(out[0]).message;
    EXPECT_EQ(std::get<Frame<Message>>(decode_packet(packet, version)).message, message)
        << describe(message);
  }
}

Bytes head_vehicle_stream() {
  Bytes stream;
  for (const Message& m : std::vector<Message>{kProgramAuthReply, test_vehicle_map(),
                                               HighFreqData{kTenOClock, 2, 0, 1.5, 2.5, 90},
                                               LowFreqData{State::wait, kTenOClock, 50, 75, 40}}) {
    const Bytes packet = encode_prefixed(m, Version::head);
    stream.insert(stream.end(), packet.begin(), packet.end());
  }
  return stream;
}

TEST(Wr8SvguiDecoder, AHeadVehicleStreamDecodesPacketByPacketHoweverItIsCut) {
  const Bytes stream = head_vehicle_stream();
  ASSERT_EQ(stream.size(), 5u + 80u + 66u + 35u);
  const auto whole = test::decode_whole<Decoder, Item>(Decoder(Version::head), stream);
  ASSERT_EQ(whole.size(), 4u);
  EXPECT_EQ(std::get<Frame<Message>>(whole[0]).raw, hex("04 02 01 02 03"));
  EXPECT_EQ(std::get<Frame<Message>>(whole[1]).raw.size(), 80u);  // length byte and 79
  EXPECT_EQ(test::raw_of_all(whole), stream);
  const auto bytewise =
      test::decode_chunked<Decoder, Item>(Decoder(Version::head), stream, {1});
  EXPECT_EQ(bytewise, whole);
}

TEST(Wr8SvguiDecoder, DataBytesAreNeverReadAsAPhantomAuthReply) {
  // HIGH-FREQ values hold 02 bytes (the steering code, 2.0 as a double);
  // read without the length byte they could pass for AUTH-REPLY packets.
  Bytes stream;
  for (int i = 0; i < 20; ++i) {
    const Bytes packet = encode_prefixed(
        HighFreqData{kTenOClock + 50u * static_cast<std::uint32_t>(i), 2, 2, 2, 2, 2}, Version::head);
    stream.insert(stream.end(), packet.begin(), packet.end());
  }
  const auto items = test::decode_chunked<Decoder, Item>(Decoder(Version::head), stream, {7, 3});
  ASSERT_EQ(items.size(), 20u);
  for (const auto& m : test::messages_of(items))
    EXPECT_TRUE(std::holds_alternative<HighFreqData>(m));
}

TEST(Wr8SvguiDecoder, AnErrorItemKeepsItsLengthByte) {
  const auto items = test::decode_whole<Decoder, Item>(Decoder(Version::head), hex("03 02 01 02"));
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(error_of(items[0]).raw, hex("03 02 01 02"));
  EXPECT_EQ(error_of(items[0]).kind, ErrorKind::bad_format);  // AUTH-REPLY one byte short
}

TEST(Wr8Svgui, DescribeNamesTheFields) {
  EXPECT_EQ(describe(Data{State::wait, kTenOClock, 100, 1.5, 80, 60}),
            "Data state=WAIT t=36000000ms encoder=100 steering=1.5 motor-battery=80 "
            "computer-battery=60");
  EXPECT_EQ(describe(Answer{4, 2}), "Answer coi=4 code=2");
  EXPECT_EQ(describe(Control{0.5, -1}), "Control x=0.5 y=-1");
  // Doubles are shown exactly, in the shortest text that reads back the same.
  EXPECT_EQ(describe(Control{0.1, 1.0 / 3}), "Control x=0.1 y=0.3333333333333333");
}

}  // namespace
}  // namespace hil::protocol::wr8::svgui
