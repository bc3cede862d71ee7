// The board's real receive path (profile `firmware`): the frames the real
// RobotClient sends and the replies the real sketch writes are the vectors
// (andrii-mazurchuk/arduino_robot_steering- at 8dcfab0; the facts are in
// docs/protocols/arduino.md, "Profiles").

#include <gtest/gtest.h>

#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "protocol/arduino/codec.hpp"
#include "protocol/arduino/sketch.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::protocol::arduino {
namespace {

SketchVerdict judge(std::string_view frame) {
  return judge_sketch_frame(frame);
}

// Expects each frame to be judged as its verdict says.
void expect_verdicts(std::initializer_list<std::pair<std::string_view, SketchVerdict>> cases) {
  for (const auto& [frame, verdict] : cases)
    EXPECT_EQ(judge(frame), verdict) << frame;
}

std::vector<SketchFrame> receive(std::string_view stream) {
  SketchReceiver receiver;
  std::vector<SketchFrame> out;
  receiver.feed(to_bytes(stream), out);
  return out;
}

std::string text_of(const Bytes& raw) {
  return std::string(raw.begin(), raw.end());
}

TEST(ArduinoSketch, TheRealClientsFramesAreRequests) {
  // robot_client.py sends a one-space payload for commands without one.
  expect_verdicts({
      {"^01|PING| *31$", SketchRequest{"01", "PING", " "}},
      {"^05|B| *67$", SketchRequest{"05", "B", " "}},
      {"^02|V|160*63$", SketchRequest{"02", "V", "160"}},
      {"^03|STATUS| *37$", SketchRequest{"03", "STATUS", " "}},
      {"^09|R|-90*7F$", SketchRequest{"09", "R", "-90"}},
  });
}

TEST(ArduinoSketch, AnEmptyPayloadIsBadFormatWithTheFramesSeq) {
  // The README's own PING: strtok finds two fields, not three.
  EXPECT_EQ(judge("^01|PING|*11$"), (SketchVerdict{SketchRefusal{"01", NackCode::bad_fmt}}));
  EXPECT_EQ(sketch_frame("01", "NACK", "BAD_FMT"), "^01|NACK|BAD_FMT*41$");
  // A first field that is not two characters long is echoed as 00.
  EXPECT_EQ(judge("^001|PING|*21$"), (SketchVerdict{SketchRefusal{"00", NackCode::bad_fmt}}));
}

TEST(ArduinoSketch, EmptyFieldsMergeAndAFourthFieldIsIgnored) {
  expect_verdicts({
      {"^01||PING| *4D$", SketchRequest{"01", "PING", " "}},
      {"^01|PING| |extra*37$", SketchRequest{"01", "PING", " "}},
  });
}

TEST(ArduinoSketch, ABadChecksumEchoesTheFirstTwoContentBytes) {
  EXPECT_EQ(judge("^zz|PING| *00$"), (SketchVerdict{SketchRefusal{"zz", NackCode::bad_cs}}));
  EXPECT_EQ(sketch_frame("zz", "NACK", "BAD_CS"), "^zz|NACK|BAD_CS*0F$");
  EXPECT_EQ(judge("^01|PING| *32$"), (SketchVerdict{SketchRefusal{"01", NackCode::bad_cs}}));
}

TEST(ArduinoSketch, ASeqThatIsNotHexIsBadSeqWithSeq00) {
  EXPECT_EQ(judge("^G1|PING| *46$"), (SketchVerdict{SketchRefusal{"00", NackCode::bad_seq}}));
  EXPECT_EQ(sketch_frame("00", "NACK", "BAD_SEQ"), "^00|NACK|BAD_SEQ*58$");
}

TEST(ArduinoSketch, LowerCaseHexIsAcceptedInTheChecksumAndTheSeq) {
  EXPECT_EQ(judge("^0a|ping| *61$"), (SketchVerdict{SketchRequest{"0a", "ping", " "}}));
  // "01||PING| " sums to 0x4D; written in lower case it still matches.
  EXPECT_EQ(judge("^01||PING| *4d$"), (SketchVerdict{SketchRequest{"01", "PING", " "}}));
}

TEST(ArduinoSketch, MalformedFramesAreDroppedWithoutAnAnswer) {
  for (const char* frame : {
           "^1*00$",          // 6 bytes: shorter than 7
           "^01|PING| 31$",   // no '*'
           "^01|V|1*0*63$",   // four characters between the first '*' and '$'
           "^01|PING| *3$",   // one checksum character
           "^01|PING| *G1$",  // checksum not hex
       }) {
    EXPECT_TRUE(std::holds_alternative<SketchDrop>(judge(frame))) << frame;
  }
}

TEST(ArduinoSketch, BytesBeforeTheStartAreIgnoredAndACaretInsideIsKept) {
  const auto out = receive("noise$^01|PING| *31$");
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(text_of(out[0].raw), "^01|PING| *31$");
  // The sketch does not restart on a second '^': it is one more byte, so
  // the checksum covers it and this frame is refused as BAD_CS.
  const auto restarted = receive("^01|PI^02|PING| *31$");
  ASSERT_EQ(restarted.size(), 1u);
  EXPECT_EQ(text_of(restarted[0].raw), "^01|PI^02|PING| *31$");
  EXPECT_EQ(restarted[0].verdict, (SketchVerdict{SketchRefusal{"01", NackCode::bad_cs}}));
}

// A V frame of exactly `size` bytes: the payload is zeros after the 1.
std::string frame_of_size(std::size_t size) {
  const std::string head = "01|V|1";
  std::string content = head + std::string(size - head.size() - 5, '0');
  return sketch_frame(content.substr(0, 2), "V", content.substr(5));
}

TEST(ArduinoSketch, NinetySixBytesFitAndTheByteAfterAFullBufferIsLost) {
  const std::string full = frame_of_size(96);
  ASSERT_EQ(full.size(), 96u);
  auto out = receive(full);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<SketchRequest>(out[0].verdict));

  // 97 bytes: dropped at the 97th, which is lost with it; the next frame
  // right after is taken whole.
  const std::string over = frame_of_size(97);
  ASSERT_EQ(over.size(), 97u);
  out = receive(over + "^05|B| *67$");
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].raw.size(), 96u);
  EXPECT_TRUE(std::holds_alternative<SketchDrop>(out[0].verdict));
  EXPECT_EQ(out[1].verdict, (SketchVerdict{SketchRequest{"05", "B", " "}}));

  // A '^' that arrives as the 97th byte is lost too: the frame it starts
  // is not seen.
  out = receive(over.substr(0, 96) + "^05|B| *67$");
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<SketchDrop>(out[0].verdict));
}

TEST(ArduinoSketch, AnyChunkingGivesTheSameFrames) {
  const std::string stream = "xx^01|PING| *31$^02|V|160*63$^01|PING|*11$^1*00$^05|B| *67$";
  const auto whole = receive(stream);
  SketchReceiver receiver;
  std::vector<SketchFrame> bytewise;
  for (const char c : stream)
    receiver.feed(to_bytes(std::string_view(&c, 1)), bytewise);
  ASSERT_EQ(bytewise.size(), whole.size());
  for (std::size_t i = 0; i < whole.size(); ++i) {
    EXPECT_EQ(bytewise[i].raw, whole[i].raw);
    EXPECT_EQ(bytewise[i].verdict, whole[i].verdict);
  }
  EXPECT_EQ(whole.size(), 5u);
  EXPECT_EQ(receiver.buffered(), 0u);
}

TEST(ArduinoSketch, RepliesAreFramedAsTheSketchWritesThem) {
  EXPECT_EQ(sketch_frame("01", "ACK", "PONG"), "^01|ACK|PONG*5E$");
  EXPECT_EQ(sketch_frame("01", "ACK", "STOPPED"), "^01|ACK|STOPPED*01$");
  EXPECT_EQ(sketch_frame("05", "ACK", "B:0"), "^05|ACK|B:0*04$");
  EXPECT_EQ(sketch_frame("01", "NACK", "BAD_V"), "^01|NACK|BAD_V*48$");
  // The content is cut at 95 characters, as snprintf into 96 bytes cuts it.
  const std::string long_payload(200, 'x');
  EXPECT_EQ(sketch_frame("01", "ACK", long_payload).size(), 1u + 95u + 4u);
}

TEST(ArduinoSketch, TheFirmwareDialectEncodesRequestsAsTheRealClientSendsThem) {
  EXPECT_EQ(encode_text(Message{0x01, Ping{}}, Dialect::firmware), "^01|PING| *31$");
  EXPECT_EQ(encode_text(Message{0x05, SonarRead{}}, Dialect::firmware), "^05|B| *67$");
  EXPECT_EQ(encode_text(Message{0x02, SetSpeed{160}}, Dialect::firmware), "^02|V|160*63$");
  // The readme dialect keeps the README's empty payload; answers are alike.
  EXPECT_EQ(encode_text(Message{0x01, Ping{}}, Dialect::readme), "^01|PING|*11$");
  EXPECT_EQ(encode_text(Message{0x01, Ack{""}}, Dialect::firmware), "^01|ACK|*48$");
  EXPECT_EQ(dialect_named("firmware"), Dialect::firmware);
  EXPECT_EQ(dialect_named(""), Dialect::firmware);
  EXPECT_EQ(dialect_named(""), kDefaultDialect);
  EXPECT_EQ(dialect_named("readme"), Dialect::readme);
  EXPECT_THROW(dialect_named("sketch"), ProfileError);
}

TEST(ArduinoSketch, TheRealClientsFramesTypeAsTheirRequestsInTheFirmwareDialect) {
  const auto typed = [](std::string_view raw, Dialect d) -> std::optional<Message> {
    const auto item = decode_frame(to_bytes(raw), d);
    if (const auto* f = std::get_if<Frame<Message>>(&item)) return f->message;
    return std::nullopt;
  };
  // robot_client.py at 8dcfab0 sends these.
  EXPECT_EQ(typed("^01|PING| *31$", Dialect::firmware), (Message{0x01, Ping{}}));
  EXPECT_EQ(typed("^05|B| *67$", Dialect::firmware), (Message{0x05, SonarRead{}}));
  EXPECT_EQ(typed("^02|V|160*63$", Dialect::firmware), (Message{0x02, SetSpeed{160}}));
  // The README's empty payload still types; a space is only the sketch's.
  EXPECT_EQ(typed("^01|PING|*11$", Dialect::firmware), (Message{0x01, Ping{}}));
  EXPECT_EQ(typed("^01|PING| *31$", Dialect::readme), std::nullopt);
  EXPECT_EQ(typed("^01|PING|  *11$", Dialect::firmware), std::nullopt) << "two spaces";
}

TEST(ArduinoSketch, PayloadNumbersAreReadAsAtolReadsThem) {
  EXPECT_EQ(sketch_atol("160"), 160);
  EXPECT_EQ(sketch_atol(" "), 0);
  EXPECT_EQ(sketch_atol("abc"), 0);
  EXPECT_EQ(sketch_atol("  -20"), -20);
  EXPECT_EQ(sketch_atol("+7"), 7);
  EXPECT_EQ(sketch_atol("12abc"), 12);
  EXPECT_EQ(sketch_atol("999"), 999);
  EXPECT_EQ(sketch_atol("99999999999"), 2147483647);
  EXPECT_EQ(sketch_atol("-99999999999"), -2147483648L);
}

}  // namespace
}  // namespace hil::protocol::arduino
