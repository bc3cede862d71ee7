#include <gtest/gtest.h>

#include "protocol/arduino/codec.hpp"
#include "tests/protocol/decoder_test_support.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::arduino {
namespace {

using test::error_at;
using test::message_at;

std::vector<Item> decode_all(std::string_view stream, DecoderOptions options = {}) {
  return test::decode_whole<Decoder, Item>(Decoder(options), to_bytes(stream));
}

// The one error a single candidate frame produces.
DecodeError single_error(std::string_view frame, DecoderOptions options = {}) {
  const auto items = decode_all(frame, options);
  EXPECT_EQ(items.size(), 1u) << frame;
  if (items.size() != 1 || !std::holds_alternative<DecodeError>(items[0])) {
    ADD_FAILURE() << frame << " did not give exactly one error";
    return {};
  }
  return std::get<DecodeError>(items[0]);
}

TEST(ArduinoDecoder, StickyPacketsInOneReadGiveEveryFrame) {
  const auto items = decode_all("^01|PING|*11$^01|ACK|OK*4C$^02|V|160*63$");
  ASSERT_EQ(items.size(), 3u);
  EXPECT_EQ(test::messages_of(items),
            (std::vector<Message>{{1, Ping{}}, {1, Ack{"OK"}}, {2, SetSpeed{160}}}));
}

TEST(ArduinoDecoder, SplitPacketIsReassembled) {
  test::expect_reassembled<Decoder>({to_bytes("^04|R"), to_bytes("|-9"), to_bytes("0*72$^05")}, 8u,
                                    Message{4, Rotate{-90}}, 3u);
}

TEST(ArduinoDecoder, LineNoiseBetweenFramesIsReportedAsGarbage) {
  // A sketch printing a boot banner, and CR/LF line endings after each frame.
  const auto items = decode_all("Robot ready\r\n^01|ACK|OK*4C$\r\n");
  ASSERT_EQ(items.size(), 3u);
  EXPECT_EQ(error_at(items, 0).kind, ErrorKind::garbage);
  EXPECT_EQ(to_string(error_at(items, 0).raw), "Robot ready\r\n");
  EXPECT_EQ(message_at(items, 1), (Message{1, Ack{"OK"}}));
  EXPECT_EQ(error_at(items, 2).kind, ErrorKind::garbage);
  EXPECT_EQ(to_string(error_at(items, 2).raw), "\r\n");
}

TEST(ArduinoDecoder, BadChecksumNamesBothValuesAndTheStreamContinues) {
  const auto items = decode_all("^02|V|160*64$^03|M|25*49$");
  ASSERT_EQ(items.size(), 2u);
  const auto& e = error_at(items, 0);
  EXPECT_EQ(e.kind, ErrorKind::bad_checksum);
  EXPECT_EQ(to_string(e.raw), "^02|V|160*64$");
  EXPECT_EQ(e.context, "V");
  EXPECT_NE(e.detail.find("checksum 64, computed 63"), std::string::npos) << e.detail;
  EXPECT_EQ(message_at(items, 1), (Message{3, Move{25}}));
}

TEST(ArduinoDecoder, LowercaseChecksumIsAcceptedButVisible) {
  const auto lenient = decode_all("^06|I|*4f$");
  ASSERT_EQ(lenient.size(), 1u);
  const auto& f = std::get<Frame<Message>>(lenient[0]);
  EXPECT_EQ(f.message, (Message{6, IrRead{}}));
  EXPECT_EQ(f.tolerated, ErrorKind::lowercase_checksum);

  const auto strict =
      single_error("^06|I|*4f$", DecoderOptions{.accept_lowercase_checksum = false});
  EXPECT_EQ(strict.kind, ErrorKind::lowercase_checksum);
  EXPECT_EQ(strict.context, "I");

  // A wrong value is a checksum error in either case.
  EXPECT_EQ(single_error("^06|I|*4e$").kind, ErrorKind::bad_checksum);
}

TEST(ArduinoDecoder, FormatErrorsSayWhatWasWrong) {
  struct Case {
    std::string frame;
    const char* detail_part;
    const char* context;
  };
  const Case cases[] = {
      {"^01|PING|11$", "no '*'", "PING"},
      {"^01|PING|*1$", "not two hex digits", "PING"},
      {"^01|PING|*1G$", "not two hex digits", "PING"},
      {frame_body("01|PING"), "expected 3 fields", "PING"},
      {frame_body("01|PING||"), "expected 3 fields", "PING"},
      {frame_body("01"), "found 1", ""},
      {frame_body("01||"), "CMD field is empty", ""},
      {frame_body("01|PI\tNG|"), "CMD has a character", ""},
      {frame_body("01|ACK|O\x01K"), "byte 0x01 at offset 1", "ACK"},
      {frame_body("01|PING|x"), "PING takes no payload", "PING"},
      {frame_body("01|M|forward"), "not a signed whole distance in cm", "M"},
      {frame_body("01|R|"), "not a signed whole angle", "R"},
      {"^$", "no '*'", ""},
  };
  for (const auto& c : cases) {
    const auto e = single_error(c.frame);
    EXPECT_EQ(e.kind, ErrorKind::bad_format) << c.frame;
    EXPECT_NE(e.detail.find(c.detail_part), std::string::npos) << c.frame << ": " << e.detail;
    EXPECT_EQ(e.context, c.context) << c.frame;
    EXPECT_EQ(nack_for(e), NackCode::bad_fmt) << c.frame;
  }
}

TEST(ArduinoDecoder, BadSequenceNumberIsItsOwnCase) {
  for (const char* body : {"G1|PING|", "1|PING|", "001|PING|", "|PING|", " 1|PING|"}) {
    const auto e = single_error(frame_body(body));
    EXPECT_EQ(e.kind, ErrorKind::bad_format) << body;
    EXPECT_EQ(e.context, "SEQ") << body;
    EXPECT_NE(e.detail.find("not two hex digits (command PING)"), std::string::npos) << e.detail;
    EXPECT_EQ(nack_for(e), NackCode::bad_seq) << body;
  }
}

TEST(ArduinoDecoder, SpeedOutOfRangeOrNotANumberIsBadValue) {
  for (const char* body : {"02|V|256", "02|V|-1", "02|V|", "02|V|fast", "02|V|1.5"}) {
    const auto e = single_error(frame_body(body));
    EXPECT_EQ(e.kind, ErrorKind::bad_value) << body;
    EXPECT_EQ(e.context, "V") << body;
    EXPECT_EQ(nack_for(e), NackCode::bad_v) << body;
  }
  EXPECT_NE(single_error(frame_body("02|V|300")).detail.find("300 is outside 0..255"),
            std::string::npos);
}

TEST(ArduinoDecoder, MoveAndRotateOutsideTheFirmwareIntAreBadValue) {
  for (const char* body : {"03|M|32768", "04|R|-32769"}) {
    const auto e = single_error(frame_body(body));
    EXPECT_EQ(e.kind, ErrorKind::bad_value) << body;
    EXPECT_NE(e.detail.find("outside -32768..32767"), std::string::npos) << e.detail;
    EXPECT_EQ(nack_for(e), NackCode::bad_fmt) << body;
  }
}

TEST(ArduinoDecoder, UnknownCommandIsUnknownCode) {
  // Lowercase tokens are the seed CLI's aliases, not wire commands.
  for (const char* cmd : {"JUMP", "ping", "HISTORY"}) {
    const auto e = single_error(frame_body(std::string("07|") + cmd + "|"));
    EXPECT_EQ(e.kind, ErrorKind::unknown_code) << cmd;
    EXPECT_EQ(e.context, cmd);
    EXPECT_EQ(nack_for(e), NackCode::bad_cmd) << cmd;
    EXPECT_EQ(sequence_of(e.raw), 0x07);
  }
}

TEST(ArduinoDecoder, ChecksumErrorMapsToBadCsAndKeepsTheSeq) {
  const auto e = single_error("^2A|S|*00$");
  EXPECT_EQ(nack_for(e), NackCode::bad_cs);
  EXPECT_EQ(sequence_of(e.raw), 0x2A);
  const auto lower = single_error("^06|I|*4f$", DecoderOptions{.accept_lowercase_checksum = false});
  EXPECT_EQ(nack_for(lower), NackCode::bad_cs);
  EXPECT_EQ(sequence_of(lower.raw), 0x06);
}

TEST(ArduinoDecoder, IncompleteFramesAreNotAnswered) {
  // A frame cut short by the next '^': the firmware never saw it end.
  const auto items = decode_all("^01|PIN^02|V|160*63$^03|M|2");
  ASSERT_EQ(items.size(), 3u);
  EXPECT_EQ(error_at(items, 0).kind, ErrorKind::bad_format);
  EXPECT_EQ(to_string(error_at(items, 0).raw), "^01|PIN");
  EXPECT_NE(error_at(items, 0).detail.find("cut short"), std::string::npos);
  EXPECT_EQ(nack_for(error_at(items, 0)), std::nullopt);
  EXPECT_EQ(message_at(items, 1), (Message{2, SetSpeed{160}}));
  EXPECT_EQ(error_at(items, 2).kind, ErrorKind::truncated);
  EXPECT_EQ(error_at(items, 2).context, "M");
  EXPECT_EQ(nack_for(error_at(items, 2)), std::nullopt);
  EXPECT_EQ(sequence_of(error_at(items, 2).raw), 0x03);
}

TEST(ArduinoDecoder, GarbageIsNeverAnswered) {
  const auto items = decode_all("$$ hello $");
  ASSERT_EQ(items.size(), 1u);
  EXPECT_EQ(error_at(items, 0).kind, ErrorKind::garbage);
  EXPECT_EQ(nack_for(error_at(items, 0)), std::nullopt);
  EXPECT_EQ(sequence_of(error_at(items, 0).raw), std::nullopt);
}

TEST(ArduinoDecoder, RunawayFrameIsBoundedByTheReceiveGuard) {
  const std::string stream = "^01|ACK|" + std::string(400, 'x') + "^02|V|160*63$";
  const auto out =
      test::decode_bytewise_within<Decoder, Item>(Decoder{}, to_bytes(stream), kMaxFrameBytes);
  EXPECT_EQ(test::count_errors(out, ErrorKind::oversized), 1u);
  EXPECT_EQ(test::messages_of(out), (std::vector<Message>{{2, SetSpeed{160}}}));
  EXPECT_EQ(nack_for(error_at(out, 0)), std::nullopt);
}

TEST(ArduinoDecoder, FirmwareModeRejectsFramesOverNinetySixBytes) {
  // 96 bytes exactly: "^01|ACK|" (8) + info + "*CS$" (4).
  const std::string fits = encode_text({1, Ack{std::string(96 - 12, 'x')}});
  const std::string too_long = encode_text({1, Ack{std::string(97 - 12, 'x')}});
  ASSERT_EQ(fits.size(), 96u);
  ASSERT_EQ(too_long.size(), 97u);

  EXPECT_EQ(test::messages_of(decode_all(fits, DecoderOptions::firmware())).size(), 1u);
  const auto firmware = decode_all(too_long, DecoderOptions::firmware());
  ASSERT_EQ(firmware.size(), 1u);
  EXPECT_EQ(error_at(firmware, 0).kind, ErrorKind::oversized);
  EXPECT_EQ(to_string(error_at(firmware, 0).raw), too_long);
  EXPECT_EQ(nack_for(error_at(firmware, 0)), std::nullopt);
  // The PC side's guard is 256 bytes, so the same frame is fine there.
  EXPECT_EQ(test::messages_of(decode_all(too_long)).size(), 1u);

  Decoder d(DecoderOptions::firmware());
  std::vector<Item> out;
  const std::string longer = encode_text({1, Ack{std::string(200, 'x')}});
  for (const char c : longer + fits) {
    d.feed(to_bytes(std::string_view(&c, 1)), out);
    EXPECT_LE(d.buffered(), kFirmwareMaxFrameBytes);
  }
  d.finish(out);
  EXPECT_EQ(test::messages_of(out), (std::vector<Message>{{1, Ack{std::string(84, 'x')}}}));
  EXPECT_EQ(test::count_errors(out, ErrorKind::oversized), 1u);
}

TEST(ArduinoDecoder, TooSmallABoundIsAConfigurationError) {
  EXPECT_THROW(Decoder(DecoderOptions{.max_frame_bytes = 9}), std::invalid_argument);
  EXPECT_NO_THROW(Decoder(DecoderOptions{.max_frame_bytes = kMinFrameBytes}));
}

TEST(ArduinoDecoder, GarbageComesOutInBoundedChunks) {
  const std::string noise(1000, 'z');
  const auto items = decode_all(noise);
  std::size_t total = 0;
  for (const auto& item : items) {
    const auto& e = std::get<DecodeError>(item);
    EXPECT_EQ(e.kind, ErrorKind::garbage);
    EXPECT_LE(e.raw.size(), kMaxFrameBytes + 1);
    total += e.raw.size();
  }
  EXPECT_EQ(total, noise.size());
}

TEST(ArduinoDecoder, NackResponseCarriesTheRequestSeq) {
  const auto cs = nack_response(single_error("^2A|S|*00$"));
  ASSERT_TRUE(cs);
  EXPECT_EQ(encode_text(*cs), "^2A|NACK|BAD_CS*7C$");
  const auto v = nack_response(single_error(frame_body("02|V|999")));
  ASSERT_TRUE(v);
  EXPECT_EQ(*v, (Message{0x02, Nack{NackCode::bad_v}}));
  // An unreadable SEQ is answered with SEQ 00.
  const auto seq = nack_response(single_error(frame_body("G1|PING|")));
  ASSERT_TRUE(seq);
  EXPECT_EQ(*seq, (Message{0x00, Nack{NackCode::bad_seq}}));
  EXPECT_FALSE(nack_response(single_error("noise")));
}

TEST(ArduinoDecoder, SequenceOfReadsOnlyAWellFormedSeqField) {
  EXPECT_EQ(sequence_of(to_bytes("^1F|PING|*00$")), 0x1F);
  EXPECT_EQ(sequence_of(to_bytes("^1f|")), 0x1F);
  EXPECT_EQ(sequence_of(to_bytes("^1G|PING|*00$")), std::nullopt);
  EXPECT_EQ(sequence_of(to_bytes("^123|PING|*00$")), std::nullopt);
  EXPECT_EQ(sequence_of(to_bytes("01|PING|*00$")), std::nullopt);
  EXPECT_EQ(sequence_of(to_bytes("^1")), std::nullopt);
}

}  // namespace
}  // namespace hil::protocol::arduino
