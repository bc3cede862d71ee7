// The timeline keeps records in arrival order and writes them as NDJSON
// with the time, source and kind first; the wire recorder turns bytes into
// frame records whose decoded fields a scenario can test.

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "harness/timeline.hpp"
#include "harness/timeline_recorder.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::harness {
namespace {

TEST(Timeline, WritesOneOrderedJsonObjectPerRecord) {
  Timeline t;
  t.add(Time(link::milliseconds(1500)), WireKind::frame,
        {{"dir", "to_car"}, {"stage", "delivered"}, {"frame", "MV:STOP"}});
  t.add(Time(link::milliseconds(1500)), ClientKind::stale);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t.records()[1].kind, ClientKind::stale);
  EXPECT_EQ(t.to_ndjson(),
            "{\"t_ms\":1500.0,\"source\":\"wire\",\"kind\":\"frame\",\"dir\":\"to_car\","
            "\"frame\":\"MV:STOP\",\"stage\":\"delivered\"}\n"
            "{\"t_ms\":1500.0,\"source\":\"client\",\"kind\":\"stale\"}\n");
}

// ------------------------------------------------------------ fields

TEST(FrameFields, DecimalNumbersBecomeNumbersAndEverythingElseStaysText) {
  EXPECT_EQ(field_value("50"), nlohmann::json(50));
  EXPECT_EQ(field_value("0"), nlohmann::json(0));
  EXPECT_EQ(field_value("-3"), nlohmann::json(-3));
  EXPECT_EQ(field_value("1.5"), nlohmann::json(1.5));
  EXPECT_EQ(field_value("0.05"), nlohmann::json(0.05));
  // Leading zeros are part of what the field says (TRK 0110, seq 03).
  EXPECT_EQ(field_value("0110"), nlohmann::json("0110"));
  EXPECT_EQ(field_value("030"), nlohmann::json("030"));
  EXPECT_EQ(field_value("1."), nlohmann::json("1."));
  EXPECT_EQ(field_value("1e3"), nlohmann::json("1e3"));
  EXPECT_EQ(field_value("-"), nlohmann::json("-"));
  EXPECT_EQ(field_value("BAD_V"), nlohmann::json("BAD_V"));
  EXPECT_EQ(field_value(""), nlohmann::json(""));
  EXPECT_EQ(field_value("123456789012345678901234567890"),
            nlohmann::json("123456789012345678901234567890"));
}

TEST(FrameFields, TheNameValuePairsOfAMessage) {
  EXPECT_EQ(message_fields("SetSpeed percent=30"), (nlohmann::json{{"percent", 30}}));
  EXPECT_EQ(message_fields("Move FWD"), nlohmann::json::object());
  EXPECT_EQ(message_fields("Status speed_percent=50 mode=MAN track=0110 rpm=0:0:0:0 +BAT=87"),
            (nlohmann::json{{"speed_percent", 50},
                            {"mode", "MAN"},
                            {"track", "0110"},
                            {"rpm", "0:0:0:0"},
                            {"BAT", 87}}));
  // Quoted values keep their spaces and lose their quotes (a number is still
  // a number, as a scenario writes it); a quoted word names nothing.
  EXPECT_EQ(message_fields("Ack seq=00 info=\"V 160 ok\""),
            (nlohmann::json{{"seq", "00"}, {"info", "V 160 ok"}}));
  EXPECT_EQ(message_fields("Ack seq=02 info=\"120\""),
            (nlohmann::json{{"seq", "02"}, {"info", 120}}));
  EXPECT_EQ(message_fields("Nack seq=0A text=\"say \\\"no\\\"\""),
            (nlohmann::json{{"seq", "0A"}, {"text", "say \\\"no\\\""}}));
  EXPECT_EQ(message_fields("reply \"LEKA name=leka state=ok\""), nlohmann::json::object());
  // The first of a name given twice (the first command of a Leka group).
  EXPECT_EQ(message_fields("led.ear.all rgb=(255,0,0) + motor.all forward speed=200 + "
                           "led.belt.all rgb=(0,0,255)"),
            (nlohmann::json{{"rgb", "(255,0,0)"}, {"speed", 200}}));
  // Odd shapes do not throw or run past the end.
  EXPECT_EQ(message_fields("x= =y \"open"), (nlohmann::json{{"x", ""}}));
}

/// A clock that stands still, for a recorder fed by hand.
class StillClock final : public link::Clock {
 public:
  Time now() const override { return Time(link::milliseconds(250)); }
};

/// The frame records a recorder of `protocol` writes for `bytes` sent in `dir`.
std::vector<Record> frames_of(const std::string& protocol, link::Direction dir,
                              const protocol::Bytes& bytes) {
  StillClock clock;
  RunTimeline timeline(clock);
  WireRecorder recorder(timeline, link::protocol_adapter(protocol));
  recorder.on_sent(clock.now(), dir, bytes);
  std::vector<Record> frames;
  for (const auto& r : timeline.timeline().records())
    if (r.kind == WireKind::frame) frames.push_back(r);
  return frames;
}

protocol::Bytes text_bytes(const std::string& text) {
  return protocol::to_bytes(text);
}

TEST(RunTimelineListeners, EachListenerSeesEachRecordOnceAndMayLeaveOrJoinWhileTold) {
  StillClock clock;
  RunTimeline timeline(clock);
  std::vector<std::string> seen;
  RunTimeline::ListenerId second = 0;
  RunTimeline::ListenerId joined = 0;
  const auto first = timeline.listen([&](const Record& r) {
    seen.push_back("first " + std::string(r.kind.name()));
    // The first record makes the second listener leave before its turn and a
    // third one join, which hears only the records after it.
    if (r.kind == StepKind::start) {
      timeline.unlisten(second);
      joined = timeline.listen([&](const Record& r2) { seen.push_back("joined " + std::string(r2.kind.name())); });
    }
  });
  second = timeline.listen([&](const Record& r) { seen.push_back("second " + std::string(r.kind.name())); });
  timeline.add(StepKind::start);
  timeline.add(StepKind::end);
  EXPECT_EQ(seen, (std::vector<std::string>{"first start", "first end", "joined end"}));
  EXPECT_EQ(timeline.timeline().size(), 2u);
  timeline.unlisten(first);
  timeline.unlisten(joined);
}

TEST(RunTimelineListeners, AListenerThatAddsARecordItselfIsRefusedAndTheTimelineGoesOn) {
  StillClock clock;
  RunTimeline timeline(clock);
  const auto id = timeline.listen([&](const Record& r) {
    if (r.kind == StepKind::start) timeline.add(ClientKind::notice);
  });
  EXPECT_THROW(timeline.add(StepKind::start), std::logic_error);
  timeline.unlisten(id);
  timeline.add(StepKind::end);
  ASSERT_EQ(timeline.timeline().size(), 2u);
  EXPECT_EQ(timeline.timeline().records()[0].kind, StepKind::start);
  EXPECT_EQ(timeline.timeline().records()[1].kind, StepKind::end);
}

TEST(WireRecorderFields, EachProtocolsDecodedFieldsAreInTheFrameRecord) {
  const auto logi = frames_of("logi", link::Direction::to_car, text_bytes("LOGI:SP:030:D5#"));
  ASSERT_EQ(logi.size(), 1u);
  EXPECT_EQ(logi[0].data.at("frame"), "SP");
  EXPECT_EQ(logi[0].data.at("text"), "LOGI:SP:030:D5#");
  EXPECT_EQ(logi[0].data.at("message"), "SetSpeed percent=30");
  EXPECT_EQ(logi[0].data.at("fields"), (nlohmann::json{{"percent", 30}}));

  const auto nack =
      frames_of("arduino", link::Direction::to_client, text_bytes("^01|NACK|BUSY*1B$"));
  ASSERT_EQ(nack.size(), 1u);
  EXPECT_EQ(nack[0].data.at("frame"), "NACK");
  EXPECT_EQ(nack[0].data.at("fields"), (nlohmann::json{{"seq", "01"}, {"text", "BUSY"}}));

  const auto data = frames_of(
      "wr8", link::Direction::to_client,
      *protocol::parse_hex("06 02 64 00 00 00 11 00 00 00 00 00 01 00 00 00 00 02 00 00 00 00 "
                           "03 64"));
  ASSERT_EQ(data.size(), 1u);
  EXPECT_EQ(data[0].data.at("frame"), "DATA");
  EXPECT_EQ(data[0].data.at("hex").get<std::string>().substr(0, 8), "06 02 64");
  EXPECT_EQ(data[0].data.at("fields"), (nlohmann::json{{"state", "STOP"},
                                                       {"timestamp_ms", 100},
                                                       {"odometry_cm", 0},
                                                       {"speed_mps", 0},
                                                       {"wheel_angle_deg", 0},
                                                       {"battery_percent", 100}}));

  const auto leka = frames_of("leka", link::Direction::to_car,
                              *protocol::parse_hex("2A 2B 2C 2D 03 21 00 C8 D0"));
  ASSERT_EQ(leka.size(), 1u);
  EXPECT_EQ(leka[0].data.at("frame"), "motor.all");
  EXPECT_EQ(leka[0].data.at("fields"), (nlohmann::json{{"speed", 200}}));
}

TEST(WireRecorderFields, AFrameWithoutFieldsOrThatDidNotDecodeHasNone) {
  const auto fb = frames_of("logi", link::Direction::to_client, text_bytes("LOGI:FB:SP:1:35#"));
  ASSERT_EQ(fb.size(), 1u);
  EXPECT_FALSE(fb[0].data.contains("fields"));
  EXPECT_EQ(fb[0].data.at("message"), "Feedback SP accepted");

  const auto bad = frames_of("logi", link::Direction::to_client, text_bytes("LOGI:FB:SP:1:36#"));
  ASSERT_EQ(bad.size(), 1u);
  EXPECT_EQ(bad[0].data.at("valid"), false);
  EXPECT_EQ(bad[0].data.at("frame"), "FB");  // only as far as the decoder got
  EXPECT_EQ(bad[0].data.at("error"), "bad_checksum");
  EXPECT_FALSE(bad[0].data.contains("fields"));
}

}  // namespace
}  // namespace hil::harness
