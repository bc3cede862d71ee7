#include <gtest/gtest.h>

#include <stdexcept>

#include "protocol/wr8/codec.hpp"
#include "tests/protocol/decoder_test_support.hpp"
#include "tests/support/hex.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::wr8 {
namespace {

using test::hex;

std::vector<Item> decode_all(std::string_view hex_stream, DecoderOptions options = {}) {
  return test::decode_whole<Decoder, Item>(Decoder(std::move(options)), hex(hex_stream));
}

using test::error_at;
using test::expect_error_at;
using test::message_at;

const Message kDrive100 = Task{1, TaskCode::drive, {Word::from_i32(100)}};

TEST(Wr8Decoder, StickyPacketsInOneReadGiveEveryPacket) {
  const auto items = decode_all("05 01 01 00 03 01 01 04 64 00 00 00 05 01 02");
  ASSERT_EQ(items.size(), 4u);
  EXPECT_EQ(test::messages_of(items),
            (std::vector<Message>{Response{1, ResponseCode::started}, Empty{}, kDrive100,
                                  Response{1, ResponseCode::completed}}));
}

TEST(Wr8Decoder, SplitPacketIsReassembledAcrossReads) {
  // The last read leaves the start of a DATA packet waiting for its header.
  test::expect_reassembled<Decoder>({hex("03 01"), hex("01 04 64"), hex("00 00 00 06 01")}, 5u,
                                    kDrive100, 2u);
}

TEST(Wr8Decoder, GarbageRunIsOneItemAndTheNextPacketDecodes) {
  const auto items = decode_all("FF 41 42 0D 0A 05 01 02");
  ASSERT_EQ(items.size(), 2u);
  expect_error_at(items, 0, {ErrorKind::garbage, std::nullopt, "5 bytes"});
  EXPECT_EQ(to_hex(error_at(items, 0).raw), "FF 41 42 0D 0A");
  EXPECT_EQ(message_at(items, 1), (Message{Response{1, ResponseCode::completed}}));
}

TEST(Wr8Decoder, LongGarbageComesInPiecesOfTheLimit) {
  const Bytes garbage(1000, 0xEE);
  DecoderOptions options;
  options.max_packet_bytes = 100;
  const auto items = test::decode_chunked<Decoder, Item>(Decoder(options), garbage, {7});
  ASSERT_EQ(items.size(), 10u);
  for (std::size_t i = 0; i < items.size(); ++i) {
    EXPECT_EQ(error_at(items, i).kind, ErrorKind::garbage);
    EXPECT_EQ(error_at(items, i).raw.size(), 100u);
  }
}

TEST(Wr8Decoder, BufferNeverExceedsTheLimit) {
  DecoderOptions options;
  options.max_packet_bytes = 40;
  Decoder d(options);
  std::vector<Item> out;
  // Garbage, a TASK declaring 200 bytes of parameters, then a DATA packet.
  Bytes stream(90, 0x99);
  const Bytes task = raw_packet(3, Bytes{1, 1, 200});
  stream.insert(stream.end(), task.begin(), task.end());
  stream.insert(stream.end(), 200, 0x11);
  const Bytes tail = hex("06 01 00 00 00 00 02 03 50");
  stream.insert(stream.end(), tail.begin(), tail.end());
  for (const std::uint8_t b : stream) {
    d.feed(ByteView(&b, 1), out);
    ASSERT_LE(d.buffered(), 40u);
  }
  d.finish(out);
  EXPECT_EQ(d.buffered(), 0u);
  EXPECT_EQ(test::messages_of(out),
            (std::vector<Message>{Data{State::run, 0, {{data_code::battery, Word{0x50}}}, {}}}));
}

TEST(Wr8Decoder, OversizedPacketIsPassedOnInPiecesThenTheStreamContinues) {
  DecoderOptions options;
  options.max_packet_bytes = 64;
  Bytes stream = raw_packet(3, Bytes{9, 1, 100});  // 104 bytes in all
  stream.insert(stream.end(), 100, 0x00);
  const Bytes next = hex("05 09 02");
  stream.insert(stream.end(), next.begin(), next.end());
  const auto items = test::decode_chunked<Decoder, Item>(Decoder(options), stream, {3});
  ASSERT_EQ(items.size(), 3u);
  expect_error_at(items, 0, {ErrorKind::oversized, "TASK", "declares 104 bytes"});
  EXPECT_EQ(error_at(items, 0).raw.size(), 64u);
  expect_error_at(items, 1, {ErrorKind::oversized, std::nullopt, "bytes 65..104 (the end)"});
  EXPECT_EQ(error_at(items, 1).raw.size(), 40u);
  EXPECT_EQ(message_at(items, 2), (Message{Response{9, ResponseCode::completed}}));
}

TEST(Wr8Decoder, PacketOfExactlyTheLimitIsAccepted) {
  DecoderOptions options;
  options.max_packet_bytes = 16;
  Task t{1, TaskCode::drive, {Word::from_i32(5)}};
  Profile p;
  p.task_parameter_count[1] = 3;  // 4 + 3 * 4 = 16 bytes
  options.profile = p;
  t.params = {Word::from_i32(1), Word::from_i32(2), Word::from_i32(3)};
  const auto items = test::decode_whole<Decoder, Item>(Decoder(options), encode(t, p));
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(message_at(items, 0), Message{t});
}

TEST(Wr8Decoder, StreamEndingInsideAPacketIsTruncated) {
  const auto items = decode_all("05 01 02 06 01 DC 05");
  ASSERT_EQ(items.size(), 2u);
  expect_error_at(items, 1, {ErrorKind::truncated, "DATA"});
  EXPECT_EQ(to_hex(error_at(items, 1).raw), "06 01 DC 05");
}

TEST(Wr8Decoder, TaskSizeNotAMultipleOfFourIsBadFormat) {
  const auto items = decode_all("03 01 01 06 01 02 03 04 05 06 05 01 02");
  ASSERT_EQ(items.size(), 2u);
  expect_error_at(items, 0, {ErrorKind::bad_format, "TASK", "multiple of 4"});
  EXPECT_EQ(error_at(items, 0).raw.size(), 10u);  // the declared length is skipped as one
  EXPECT_EQ(message_at(items, 1), (Message{Response{1, ResponseCode::completed}}));
}

TEST(Wr8Decoder, SettingsSizeNotAMultipleOfFiveIsBadFormat) {
  const auto items = decode_all("04 01 04 00 00 00 00");
  ASSERT_EQ(items.size(), 1u);
  expect_error_at(items, 0, {ErrorKind::bad_format, "SETTINGS", "multiple of 5"});
}

TEST(Wr8Decoder, TaskWithTheWrongParameterCountIsBadFormat) {
  const auto items = decode_all("03 01 01 00 03 01 03 04 00 00 00 00");
  ASSERT_EQ(items.size(), 2u);
  expect_error_at(items, 0, {ErrorKind::bad_format, std::nullopt, "drive takes 1 parameter"});
  expect_error_at(items, 1, {ErrorKind::bad_format, std::nullopt, "blink takes 0 parameters"});
}

TEST(Wr8Decoder, UnknownTaskCodeIsSkippedAsAWholePacket) {
  const auto items = decode_all("03 01 09 04 01 02 03 04 05 01 02");
  ASSERT_EQ(items.size(), 2u);
  expect_error_at(items, 0, {ErrorKind::unknown_code, "TASK", "task code 9"});
  EXPECT_EQ(error_at(items, 0).raw.size(), 8u);
  EXPECT_EQ(message_at(items, 1), (Message{Response{1, ResponseCode::completed}}));
}

TEST(Wr8Decoder, UnknownSettingTypeAndResponseCodeAreUnknownCode) {
  const auto items = decode_all("04 01 05 07 00 00 00 00 05 02 03");
  ASSERT_EQ(items.size(), 2u);
  expect_error_at(items, 0, {ErrorKind::unknown_code, std::nullopt, "setting type 7"});
  expect_error_at(items, 1, {ErrorKind::unknown_code, "RESPONSE"});
}

TEST(Wr8Decoder, StateOutsideTheTableIsBadValue) {
  const auto items = decode_all("02 01 01 04 06 09 00 00 00 00 00");
  ASSERT_EQ(items.size(), 2u);
  expect_error_at(items, 0, {ErrorKind::bad_value, "AUTH-REPLY"});
  expect_error_at(items, 1, {ErrorKind::bad_value, "DATA", "state code 9"});
}

TEST(Wr8Decoder, DataEntryRunningPastItsBlockIsBadFormat) {
  // Block of 3 bytes: odometry code then only 2 of its 4 value bytes.
  const auto items = decode_all("06 01 00 00 00 00 03 00 01 02 05 01 02");
  ASSERT_EQ(items.size(), 2u);
  expect_error_at(items, 0, {ErrorKind::bad_format, std::nullopt, "needs 4 value bytes"});
  EXPECT_EQ(message_at(items, 1), (Message{Response{1, ResponseCode::completed}}));
}

TEST(Wr8Decoder, UnknownDataCodeKeepsTheRestOfTheBlockAndStaysInSync) {
  const auto items = decode_all("06 01 00 00 00 00 07 03 4B 09 01 02 03 04 05 01 02");
  ASSERT_EQ(items.size(), 2u);
  const auto& f = std::get<Frame<Message>>(items[0]);
  EXPECT_EQ(f.tolerated, ErrorKind::unknown_code);
  const auto& d = std::get<Data>(f.message);
  EXPECT_EQ(d.values, (std::vector<DataValue>{{data_code::battery, Word{75}}}));
  EXPECT_EQ(to_hex(d.unparsed), "09 01 02 03 04");
  EXPECT_EQ(message_at(items, 1), (Message{Response{1, ResponseCode::completed}}));
}

TEST(Wr8Decoder, ExtendedProfileSizesANewDataCode) {
  DecoderOptions options;
  options.profile.data_parameters.push_back(
      DataParameter{9, "temperature", 2, ValueType::signed_int, "dC"});
  const auto items = decode_all("06 01 00 00 00 00 03 09 FE FF", options);
  ASSERT_EQ(items.size(), 1u);
  const auto& f = std::get<Frame<Message>>(items[0]);
  EXPECT_FALSE(f.tolerated.has_value());
  EXPECT_EQ(describe(f.message, options.profile),
            "Data state=RUN timestamp_ms=0 temperature_dC=-2");
}

TEST(Wr8Decoder, EntriesModeUnknownDataCodeCutsThePacketThere) {
  DecoderOptions options;
  options.profile.block_unit = BlockSizeUnit::entries;
  // Two entries declared; the second has code 9, which cannot be sized.
  const auto items = decode_all("06 01 00 00 00 00 02 03 4B 09 05 01 02", options);
  ASSERT_EQ(items.size(), 2u);
  expect_error_at(items, 0, {ErrorKind::unknown_code, std::nullopt, "resumes after this byte"});
  EXPECT_EQ(to_hex(error_at(items, 0).raw), "06 01 00 00 00 00 02 03 4B 09");
  // The byte after the cut happens to start a packet here; in general it may not.
  EXPECT_EQ(message_at(items, 1), (Message{Response{1, ResponseCode::completed}}));
}

TEST(Wr8Decoder, VehicleSideDecoderTreatsVehiclePacketsAsUnknownCodes) {
  DecoderOptions options;
  options.sender = Sender::gui;  // decoding what the GUI sends
  const auto items = decode_all("06 05 02 03 01 01 04 64 00 00 00", options);
  ASSERT_EQ(items.size(), 2u);
  expect_error_at(items, 0, {ErrorKind::unknown_code, "DATA", "GUI does not send"});
  EXPECT_EQ(to_hex(error_at(items, 0).raw), "06 05 02");  // one item for the run
  EXPECT_EQ(message_at(items, 1), kDrive100);
}

TEST(Wr8Decoder, GuiSideDecoderSkipsTaskBytesAndFindsTheResponse) {
  DecoderOptions options;
  options.sender = Sender::vehicle;
  const auto items = decode_all("03 01 03 05 01 02", options);
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(error_at(items, 0).kind, ErrorKind::unknown_code);
  EXPECT_EQ(to_hex(error_at(items, 0).raw), "03 01 03");
  EXPECT_EQ(message_at(items, 1), (Message{Response{1, ResponseCode::completed}}));

  // Without the filter the same bytes start a TASK that eats the response.
  const auto any = decode_all("03 01 03 05 01 02");
  EXPECT_TRUE(test::messages_of(any).empty());
}

TEST(Wr8Decoder, BigEndianProfileReadsValuesTheOtherWayRound) {
  DecoderOptions options;
  options.profile.byte_order = ByteOrder::big;
  const auto items = decode_all("03 01 01 04 00 00 00 64", options);
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(message_at(items, 0), kDrive100);
  // The same bytes in the default profile are 0x64000000 cm.
  EXPECT_EQ(std::get<Task>(message_at(decode_all("03 01 01 04 00 00 00 64"), 0)).params[0].bits,
            0x64000000u);
}

// Without a checksum some corruptions cannot be noticed: these tests pin
// down which.
TEST(Wr8Decoder, ChangedValueByteGoesUnnoticedButTheStreamStaysInSync) {
  const auto items = decode_all("03 01 01 04 65 00 00 00 05 01 02");
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(message_at(items, 0), (Message{Task{1, TaskCode::drive, {Word::from_i32(101)}}}));
  EXPECT_EQ(message_at(items, 1), (Message{Response{1, ResponseCode::completed}}));
}

TEST(Wr8Decoder, ChangedSizeByteDesynchronisesUntilAPacketBoundaryIsFoundAgain) {
  // DATA size 0x11 turned into 0x13: the packet swallows the next two bytes
  // ("05 01"), and the lone "02" left over is read as an AUTH-REPLY start.
  const auto items = decode_all(
      "06 01 DC 05 00 00 13 00 78 00 00 00 01 00 00 00 3F 02 00 00 20 C1 03 57 05 01 02 "
      "FF FF FF");
  ASSERT_GE(items.size(), 2u);
  const auto& first = std::get<Frame<Message>>(items[0]);
  EXPECT_EQ(first.tolerated, ErrorKind::unknown_code);  // 05 is no DATA code
  EXPECT_EQ(to_hex(std::get<Data>(first.message).unparsed), "05 01");
  EXPECT_EQ(error_at(items, 1).kind, ErrorKind::bad_value);  // "02 FF FF FF": state 255
}

TEST(Wr8Decoder, ChangedCodeByteIsNoticedButTheRestOfThePacketMayBeMisread) {
  // TASK code 03 turned into E3: E3 is garbage, then "02 02 04 F1" reads as
  // an AUTH-REPLY with state 0xF1, and "FF FF FF" is garbage again.
  const auto items = decode_all("E3 02 02 04 F1 FF FF FF 05 01 02");
  ASSERT_EQ(items.size(), 4u);
  EXPECT_EQ(error_at(items, 0).kind, ErrorKind::garbage);
  EXPECT_EQ(error_at(items, 1).kind, ErrorKind::bad_value);
  EXPECT_EQ(error_at(items, 2).kind, ErrorKind::garbage);
  EXPECT_EQ(message_at(items, 3), (Message{Response{1, ResponseCode::completed}}));
}

TEST(Wr8Decoder, ChangedCodeByteToAnotherPacketCodeCanYieldPhantomPackets) {
  // RESPONSE code 05 turned into 01: an 11-byte AUTH swallows three
  // responses, and the leftover bytes read as a plausible AUTH-REPLY.
  const auto items = decode_all("01 01 02 05 01 02 05 02 02 05 03 02 05 04 02");
  const auto messages = test::messages_of(items);
  ASSERT_EQ(messages.size(), 2u);
  EXPECT_TRUE(std::holds_alternative<Auth>(messages[0]));
  EXPECT_EQ(messages[1], (Message{AuthReply{5, 4, State::stop}}));
}

TEST(Wr8Decoder, ConfigurationErrorsThrowAtConstruction) {
  DecoderOptions small;
  small.max_packet_bytes = 10;
  EXPECT_THROW(Decoder{small}, std::invalid_argument);
  DecoderOptions odd;
  odd.profile.data_parameters.push_back(DataParameter{8, "wide", 3, ValueType::unsigned_int, ""});
  EXPECT_THROW(Decoder{odd}, std::invalid_argument);
  DecoderOptions twice;
  twice.profile.data_parameters.push_back(DataParameter{1, "again", 4, ValueType::float32, ""});
  EXPECT_THROW(Decoder{twice}, std::invalid_argument);
}

TEST(Wr8Decoder, DefaultLimitIsTheLongestPacketTheProfileCanDeclare) {
  EXPECT_EQ(Decoder{}.max_buffered(), 262u);
  DecoderOptions options;
  options.profile.block_unit = BlockSizeUnit::entries;
  EXPECT_EQ(Decoder{options}.max_buffered(), 7u + 255u * 5u);
}

TEST(Wr8Encode, RefusesWhatThePacketCannotCarry) {
  EXPECT_THROW(encode(Task{1, TaskCode::drive, {}}), std::invalid_argument);
  EXPECT_THROW(encode(Task{1, static_cast<TaskCode>(9), {}}), std::invalid_argument);
  EXPECT_THROW(encode(Data{State::run, 0, {{data_code::battery, Word{300}}}, {}}),
               std::invalid_argument);
  EXPECT_THROW(encode(Data{State::run, 0, {{42, Word{1}}}, {}}), std::invalid_argument);
  EXPECT_THROW(encode(Settings{1, std::vector<Setting>(52)}), std::invalid_argument);
  EXPECT_NO_THROW(encode(Settings{1, std::vector<Setting>(51)}));
  EXPECT_THROW(encode(Data{State::run, 0, {}, Bytes{0x00, 0x01}}), std::invalid_argument);
  Profile entries;
  entries.block_unit = BlockSizeUnit::entries;
  EXPECT_THROW(encode(Data{State::run, 0, {}, Bytes{0x09}}, entries), std::invalid_argument);
  EXPECT_NO_THROW(encode(Settings{1, std::vector<Setting>(255)}, entries));
}

TEST(Wr8Encode, UncheckedEncodeBuildsPacketsTheDecoderRejects) {
  const Bytes b = encode_unchecked(Task{1, TaskCode::drive, {}});
  EXPECT_EQ(to_hex(b), "03 01 01 00");
  const auto item = decode_packet(b);
  EXPECT_EQ(std::get<DecodeError>(item).kind, ErrorKind::bad_format);
  EXPECT_EQ(to_hex(encode_unchecked(Response{1, static_cast<ResponseCode>(7)})), "05 01 07");
  EXPECT_EQ(to_hex(raw_packet(4, hex("01 03 00"))), "04 01 03 00");
}

TEST(Wr8Values, FormatAndParseFollowTheirType) {
  EXPECT_EQ(parse_value("-15", ValueType::signed_int), Word::from_i32(-15));
  EXPECT_EQ(parse_value("0.5", ValueType::float32), Word::from_f32(0.5f));
  EXPECT_EQ(parse_value("0x3F000000", ValueType::signed_int), Word{0x3F000000});
  EXPECT_EQ(parse_value("255", ValueType::unsigned_int, 1), Word{255});
  EXPECT_EQ(parse_value("256", ValueType::unsigned_int, 1), std::nullopt);
  EXPECT_EQ(parse_value("-1", ValueType::unsigned_int), std::nullopt);
  EXPECT_EQ(parse_value("1.5", ValueType::signed_int), std::nullopt);
  EXPECT_EQ(parse_value("2147483648", ValueType::signed_int), std::nullopt);
  EXPECT_EQ(parse_value("0x1FF", ValueType::unsigned_int, 1), std::nullopt);
  EXPECT_EQ(format_value(Word{0xFE}, ValueType::signed_int, 1), "-2");
  EXPECT_EQ(format_value(Word::from_f32(-10.0f), ValueType::float32), "-10");
  EXPECT_EQ(format_value(Word::from_i32(-1), ValueType::unsigned_int), "4294967295");
}

}  // namespace
}  // namespace hil::protocol::wr8
