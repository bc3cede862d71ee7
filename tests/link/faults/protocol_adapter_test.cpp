#include "link/protocol_adapter.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>

#include "protocol/arduino/codec.hpp"
#include "protocol/common/car_profile.hpp"
#include "protocol/leka/codec.hpp"
#include "protocol/logi/codec.hpp"
#include "protocol/wr8/codec.hpp"
#include "protocol/wr8/svgui.hpp"
#include "tests/link/faults/fault_test_support.hpp"

namespace hil::link {
namespace {

using protocol::Bytes;
using protocol::to_bytes;
using test::concat;
using test::decode;

std::string text_of(const Bytes& frame, std::optional<ByteRange> r) {
  if (!r) return "<none>";
  return std::string(frame.begin() + static_cast<std::ptrdiff_t>(r->first),
                     frame.begin() + static_cast<std::ptrdiff_t>(r->second));
}

std::vector<std::string> kinds(const std::vector<WireFrame>& frames) {
  std::vector<std::string> out;
  for (const auto& f : frames)
    out.push_back(f.kind);
  return out;
}

TEST(ProtocolAdapter, UnknownProtocolNamesTheKnownOnes) {
  try {
    protocol_adapter("canbus");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), testing::HasSubstr("canbus"));
    EXPECT_THAT(e.what(), testing::HasSubstr("logi, wr8, arduino, leka, raw"));
  }
}

TEST(ProtocolAdapter, LogiKindsCarryTheArgumentOfStMdMv) {
  namespace logi = protocol::logi;
  const Bytes stream = concat({logi::encode(logi::SetRun{true}), logi::encode(logi::SetSpeed{50}),
                               logi::encode(logi::Move{logi::Direction::fwd}),
                               logi::encode(logi::SetMode{logi::Mode::manual}),
                               logi::encode(logi::Feedback{logi::Command::st, true}),
                               logi::encode(logi::Status{}), logi::encode(logi::SetStation{2})});
  const auto frames = decode("logi", stream);
  EXPECT_THAT(kinds(frames),
              testing::ElementsAre("ST:RUN", "SP", "MV:FWD", "MD:MAN", "FB:ST", "STAT", "GS"));
  for (const auto& f : frames)
    EXPECT_TRUE(f.valid) << f.text;
  EXPECT_EQ(frames[1].text, logi::describe(logi::SetSpeed{50}));
}

TEST(ProtocolAdapter, LogiChecksumAndFields) {
  const auto logi = protocol_adapter("logi");
  const Bytes frame = to_bytes(protocol::logi::frame_text("SP:050"));
  const std::string cs = protocol::logi::frame_text("SP:050").substr(frame.size() - 3, 2);
  EXPECT_EQ(text_of(frame, logi->checksum_field(frame)), cs);
  EXPECT_EQ(text_of(frame, logi->field(frame, "payload")), "SP:050");
  EXPECT_EQ(text_of(frame, logi->field(frame, "body")), "SP:050");
  EXPECT_EQ(text_of(frame, logi->field(frame, "code")), "SP");
  EXPECT_EQ(text_of(frame, logi->field(frame, "value")), "050");
  EXPECT_FALSE(logi->field(frame, "seq"));
  EXPECT_FALSE(logi->checksum_field(to_bytes("garbage")));
  EXPECT_THAT(logi->field_names(), testing::IsSupersetOf({"payload", "body", "code", "value"}));
}

TEST(ProtocolAdapter, ArduinoKindIsTheCmdTokenAndFieldsAreFound) {
  namespace arduino = protocol::arduino;
  const Bytes v = arduino::encode(arduino::Message{2, arduino::SetSpeed{160}});
  const Bytes ack = arduino::encode(arduino::Message{2, arduino::Ack{"ok"}});
  const Bytes nack = arduino::encode(arduino::Message{3, arduino::Nack{arduino::NackCode::bad_cs}});
  EXPECT_THAT(kinds(decode("arduino", concat({v, ack, nack}))),
              testing::ElementsAre("V", "ACK", "NACK"));

  const auto a = protocol_adapter("arduino");
  ASSERT_EQ(protocol::to_string(v), "^02|V|160*63$");
  EXPECT_EQ(text_of(v, a->checksum_field(v)), "63");
  EXPECT_EQ(text_of(v, a->field(v, "seq")), "02");
  EXPECT_EQ(text_of(v, a->field(v, "cmd")), "V");
  EXPECT_EQ(text_of(v, a->field(v, "payload")), "160");
  EXPECT_EQ(text_of(v, a->field(v, "body")), "02|V|160");
}

TEST(ProtocolAdapter, Wr8KindIsThePacketNameAndThereIsNoChecksum) {
  const auto packets = std::vector<Bytes>{*protocol::parse_hex("01 48 49 4C 2D 57 52 38 2D 30 31"),
                                          *protocol::parse_hex("02 08 01 03"),
                                          *protocol::parse_hex("03 01 01 04 64 00 00 00"),
                                          *protocol::parse_hex("05 01 02"),
                                          *protocol::parse_hex("06 03 00 00 00 00 00"),
                                          *protocol::parse_hex("00")};
  EXPECT_THAT(kinds(decode("wr8", concat(packets))),
              testing::ElementsAre("AUTH", "AUTH_REPLY", "TASK", "RESPONSE", "DATA", "EMPTY"));
  const auto w = protocol_adapter("wr8");
  const Bytes task = packets[2];
  EXPECT_FALSE(w->checksum_field(task));
  EXPECT_EQ(w->field(task, "code"), (ByteRange{0, 1}));
  EXPECT_EQ(w->field(task, "coi"), (ByteRange{1, 2}));
  EXPECT_EQ(w->field(task, "payload"), (ByteRange{1, task.size()}));
  EXPECT_FALSE(w->field(packets[4], "coi"));  // DATA has none
}

TEST(ProtocolAdapter, LekaKindIsTheFirstCommandAndTheChecksumTheLastByte) {
  const Bytes frame = *protocol::parse_hex("2A 2B 2C 2D 05 15 00 FF 00 00 41");
  const auto frames = decode("leka", frame);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_TRUE(frames[0].valid);
  EXPECT_EQ(frames[0].kind, "led.belt.single");
  const auto l = protocol_adapter("leka");
  EXPECT_EQ(l->checksum_field(frame), (ByteRange{10, 11}));
  EXPECT_EQ(l->field(frame, "length"), (ByteRange{4, 5}));
  EXPECT_EQ(l->field(frame, "group"), (ByteRange{5, 10}));
  EXPECT_FALSE(l->checksum_field(*protocol::parse_hex("2A 2B 2C 2D 09 15 00 FF 00 00 41")));
}

// LOGI and Arduino frames are text, so a corrupt rule keeps their
// characters in class; the others are bytes.
TEST(ProtocolAdapter, TextProtocolsSayTheirFramesAreText) {
  EXPECT_TRUE(protocol_adapter("logi")->text_frames());
  EXPECT_TRUE(protocol_adapter("logi", "firmware")->text_frames());
  EXPECT_TRUE(protocol_adapter("arduino")->text_frames());
  EXPECT_TRUE(protocol_adapter("arduino", "readme")->text_frames());
  EXPECT_FALSE(protocol_adapter("wr8")->text_frames());
  EXPECT_FALSE(protocol_adapter("wr8", "svgui-2019")->text_frames());
  EXPECT_FALSE(protocol_adapter("leka")->text_frames());
  EXPECT_FALSE(protocol_adapter("leka", "comspecs-v3")->text_frames());
  EXPECT_FALSE(protocol_adapter("raw")->text_frames());
}

// Profiles (protocol/common/car_profile.hpp): the adapter frames and judges
// by the car's profile, and says which one it is.
TEST(ProtocolAdapter, EachAdapterNamesItsProfile) {
  EXPECT_EQ(protocol_adapter("logi")->profile(), "guide");
  EXPECT_EQ(protocol_adapter("logi", "firmware")->profile(), "firmware");
  EXPECT_EQ(protocol_adapter("wr8")->profile(), "document");
  EXPECT_EQ(protocol_adapter("arduino")->profile(), "firmware");
  EXPECT_EQ(protocol_adapter("leka")->profile(), "readme");
  EXPECT_EQ(protocol_adapter("raw")->profile(), "");
  EXPECT_EQ(protocol_adapter("arduino", "readme")->profile(), "readme");
  EXPECT_EQ(protocol_adapter("leka", "comspecs-v3")->profile(), "comspecs-v3");
  EXPECT_EQ(protocol_adapter("leka", "")->profile(), "readme");
  EXPECT_EQ(protocol_adapter("wr8", "document")->profile(), "document");
  EXPECT_EQ(protocol_adapter("wr8", "svgui-2019")->profile(), "svgui-2019");
  EXPECT_EQ(protocol_adapter("wr8", "svgui-head")->profile(), "svgui-head");
  EXPECT_EQ(protocol_adapter("wr8", "svgui-head")->name(), "wr8");
  try {
    protocol_adapter("leka", "yaml");
    FAIL() << "no exception";
  } catch (const protocol::ProfileError& e) {
    EXPECT_STREQ(
        e.what(),
        "leka has no profile 'yaml'; its profiles are readme (the default) and comspecs-v3");
  }
  EXPECT_THROW(protocol_adapter("raw", "firmware"), protocol::ProfileError);
}

TEST(ProtocolAdapter, LekaComspecsProfileFramesTheGeneratorsDemo) {
  const Bytes demo = *protocol::parse_hex("2A 2B 2C 2D 05 16 12 64 96 C8 77");
  std::vector<WireFrame> frames;
  protocol_adapter("leka", "comspecs-v3")->splitter()->feed(demo, frames);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_TRUE(frames[0].valid) << frames[0].text;
  EXPECT_EQ(frames[0].kind, "led.belt.single");
  EXPECT_EQ(frames[0].text, "led.belt.single led=18 rgb=(100,150,200)");
  const auto readme = decode("leka", demo);
  ASSERT_EQ(readme.size(), 1U);
  EXPECT_FALSE(readme[0].valid);
}

// Towards the board, profile firmware judges each frame as the real sketch
// (arduino.ino at 8dcfab0) does; every byte is still in exactly one frame.
TEST(ProtocolAdapter, ArduinoFirmwareProfileJudgesFramesAsTheSketch) {
  const auto adapter = protocol_adapter("arduino", "firmware");
  const Bytes stream = to_bytes("^01|PING| *31$^01|PING|*11$xx^05|B| *67$");
  std::vector<WireFrame> frames;
  const auto splitter = adapter->splitter_for(Direction::to_car);
  splitter->feed(stream, frames);
  splitter->finish(frames);
  Bytes joined;
  for (const auto& f : frames)
    joined.insert(joined.end(), f.raw.begin(), f.raw.end());
  EXPECT_EQ(joined, stream);
  ASSERT_EQ(frames.size(), 4U);
  // The real client's PING: one space of payload, taken.
  EXPECT_TRUE(frames[0].valid) << frames[0].text;
  EXPECT_EQ(frames[0].kind, "PING");
  // The README's PING: an empty payload, refused with BAD_FMT.
  EXPECT_FALSE(frames[1].valid);
  // Its error kind (before the ':') is the decoder's name for the NACK.
  EXPECT_EQ(frames[1].text, "bad_format: refused by the firmware: NACK BAD_FMT");
  EXPECT_FALSE(frames[2].valid);  // garbage
  EXPECT_TRUE(frames[3].valid) << frames[3].text;
  EXPECT_EQ(frames[3].kind, "B");
  // The readme profile judges the same two PINGs the other way round.
  const auto readme = decode("arduino", to_bytes("^01|PING| *31$^01|PING|*11$"));
  ASSERT_EQ(readme.size(), 2U);
  EXPECT_FALSE(readme[0].valid);
  EXPECT_TRUE(readme[1].valid);
}

TEST(ProtocolAdapter, InvalidBytesBecomeInvalidFramesWithTheDecoderError) {
  const Bytes bad = to_bytes("LOGI:SP:050:00#");
  const auto frames = decode("logi", concat({to_bytes("xx"), bad}));
  ASSERT_EQ(frames.size(), 2U);
  EXPECT_FALSE(frames[0].valid);
  EXPECT_FALSE(frames[1].valid);
  EXPECT_EQ(frames[1].raw, bad);
  EXPECT_THAT(frames[1].text, testing::StartsWith("bad_checksum"));
}

TEST(ProtocolAdapter, TheSketchsRefusalsCarryTheDecodersErrorKind) {
  // The sketch answers a checksum mismatch NACK BAD_CS; the frame's error
  // kind is bad_checksum in the firmware profile as in the readme one.
  const auto adapter = protocol_adapter("arduino", "firmware");
  std::vector<WireFrame> frames;
  const auto splitter = adapter->splitter_for(Direction::to_car);
  splitter->feed(to_bytes("^00|V|160*51$^01|JUMP| *23$"), frames);
  ASSERT_EQ(frames.size(), 2U);
  EXPECT_FALSE(frames[0].valid);
  EXPECT_EQ(frames[0].text, "bad_checksum: refused by the firmware: NACK BAD_CS");
  EXPECT_TRUE(frames[1].valid) << "an unknown command is a frame the sketch answers BAD_CMD to";
}

TEST(ProtocolAdapter, SplittingDoesNotDependOnChunking) {
  namespace logi = protocol::logi;
  const Bytes stream =
      concat({to_bytes("noise"), logi::encode(logi::SetSpeed{7}), to_bytes("LOGI:x"),
              logi::encode(logi::Status{}), logi::encode(logi::SetRun{false})});
  for (const std::string name : {"logi", "arduino", "wr8", "leka"}) {
    const auto whole = decode(name, stream);
    auto splitter = protocol_adapter(name)->splitter();
    std::vector<WireFrame> bytewise;
    for (const auto b : stream)
      splitter->feed(protocol::ByteView(&b, 1), bytewise);
    splitter->finish(bytewise);
    ASSERT_EQ(bytewise.size(), whole.size()) << name;
    Bytes joined;
    for (std::size_t i = 0; i < whole.size(); ++i) {
      EXPECT_EQ(bytewise[i].raw, whole[i].raw) << name;
      EXPECT_EQ(bytewise[i].kind, whole[i].kind) << name;
      joined.insert(joined.end(), whole[i].raw.begin(), whole[i].raw.end());
    }
    EXPECT_EQ(joined, stream) << name << ": every byte lands in exactly one frame";
  }
}

TEST(ProtocolAdapter, LekaRobotRepliesAreCutAtLineEnds) {
  const auto leka = protocol_adapter("leka");
  auto splitter = leka->splitter_for(Direction::to_client);
  std::vector<WireFrame> frames;
  splitter->feed(to_bytes("LEKA name=leka"), frames);
  EXPECT_TRUE(frames.empty());
  EXPECT_EQ(splitter->buffered(), 14U);
  splitter->feed(to_bytes("\r\nLEKA x\r\ntail"), frames);
  ASSERT_EQ(frames.size(), 2U);
  EXPECT_TRUE(frames[0].valid);
  EXPECT_EQ(frames[0].kind, "reply");
  EXPECT_EQ(frames[0].raw, to_bytes("LEKA name=leka\r\n"));
  EXPECT_EQ(frames[1].raw, to_bytes("LEKA x\r\n"));
  splitter->finish(frames);
  ASSERT_EQ(frames.size(), 3U);
  EXPECT_FALSE(frames[2].valid);
  EXPECT_EQ(frames[2].raw, to_bytes("tail"));
  // A run with no line end is bounded like a command frame.
  auto bounded = leka->splitter_for(Direction::to_client);
  frames.clear();
  bounded->feed(Bytes(300, 'x'), frames);
  ASSERT_EQ(frames.size(), 2U);
  EXPECT_FALSE(frames[0].valid);
  EXPECT_EQ(frames[0].raw.size(), 128U);
  EXPECT_EQ(bounded->buffered(), 44U);
  // The robot's side still gets command frames.
  auto to_robot = leka->splitter_for(Direction::to_car);
  frames.clear();
  to_robot->feed(Bytes{0x2A, 0x2B, 0x2C, 0x2D, 0x01, 0x70, 0x70}, frames);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0].kind, "info");
}

TEST(ProtocolAdapter, Wr8AdapterFramesByTheVehiclesOwnProfile) {
  namespace wr8 = protocol::wr8;
  wr8::Profile profile;
  profile.byte_order = wr8::ByteOrder::big;
  profile.block_unit = wr8::BlockSizeUnit::entries;
  const wr8::Task task{3, wr8::TaskCode::drive, {wr8::Word::from_i32(100)}};
  const Bytes stream = concat({wr8::encode(task, profile), wr8::encode(task, profile)});
  const auto split = [&](const std::shared_ptr<const ProtocolAdapter>& adapter) {
    auto splitter = adapter->splitter();
    std::vector<WireFrame> frames;
    splitter->feed(stream, frames);
    splitter->finish(frames);
    return frames;
  };
  const auto own = split(wr8_adapter(profile));
  ASSERT_EQ(own.size(), 2U);
  EXPECT_TRUE(own[0].valid);
  EXPECT_EQ(own[0].kind, "TASK");
  EXPECT_EQ(own[0].raw, wr8::encode(task, profile));
  // The default profile reads the size byte (1 entry) as 1 byte and cuts the
  // packets in the wrong places.
  const auto standard = split(protocol_adapter("wr8"));
  EXPECT_FALSE(standard.size() == 2U && standard[0].valid && standard[1].valid);
}

// ---- WR8 as the real programs send it (smart_vehicle_gui 8d80e92 and
// 431e8d4): a length byte before every packet, which the adapter frames by.

namespace svgui = protocol::wr8::svgui;

Bytes hex(std::string_view text) {
  return *protocol::parse_hex(text);
}

const svgui::Data kData{protocol::wr8::State::run, 36000000, 120, 1.5, 87, 95};
const svgui::HighFreqData kHighFreq{36000000, 1.5, -10, 0.25, 0.5, 90};
const svgui::LowFreqData kLowFreq{protocol::wr8::State::wait, 36000000, 87, 95, 41.5};

std::vector<WireFrame> decode_with(std::string_view profile, const Bytes& stream) {
  return decode(*protocol_adapter("wr8", profile), stream);
}

TEST(ProtocolAdapter, SvguiPacketsAreFramedWithTheirLengthByte) {
  // The GUIs' logins and the vehicles' fixed reply, byte for byte.
  const Bytes auth_2019 = hex("0B 01 6B 6F 6E 6E 69 63 68 69 77 61");  // 0B 01 konnichiwa
  const Bytes auth_head = hex("0C 01 6B 6F 6E 6E 69 63 68 69 77 61 00");
  const Bytes reply = hex("04 02 01 02 03");
  ASSERT_EQ(
      svgui::encode_prefixed(svgui::Auth{protocol::to_bytes("konnichiwa")}, svgui::Version::v2019),
      auth_2019);
  ASSERT_EQ(svgui::encode_prefixed(svgui::kProgramAuthReply, svgui::Version::head), reply);

  const auto old = decode_with("svgui-2019", concat({auth_2019, reply}));
  ASSERT_EQ(old.size(), 2U);
  EXPECT_EQ(kinds(old), (std::vector<std::string>{"AUTH", "AUTH_REPLY"}));
  EXPECT_TRUE(old[0].valid && old[1].valid) << old[0].text << " / " << old[1].text;
  EXPECT_EQ(old[0].raw, auth_2019) << "the length byte is part of the frame";
  EXPECT_EQ(old[1].raw, reply);
  EXPECT_EQ(old[1].text, "AuthReply device=1 id=2 state=WAIT");

  const auto head = decode_with("svgui-head", concat({auth_head, reply}));
  ASSERT_EQ(head.size(), 2U);
  EXPECT_TRUE(head[0].valid) << head[0].text;
  EXPECT_EQ(head[0].raw, auth_head);
  EXPECT_EQ(head[0].text, "Auth text=\"konnichiwa\\x00\"");
  EXPECT_EQ(head[1].kind, "AUTH_REPLY");
}

TEST(ProtocolAdapter, SvguiDataPacketsAreWholeFramesOfTheirDocumentedSizes) {
  const Bytes data = svgui::encode_prefixed(kData, svgui::Version::v2019);
  const Bytes high = svgui::encode_prefixed(kHighFreq, svgui::Version::head);
  const Bytes low = svgui::encode_prefixed(kLowFreq, svgui::Version::head);
  // 42, 65 and 34 packet bytes after the length byte; big-endian values.
  EXPECT_EQ(Bytes(data.begin(), data.begin() + 15),
            hex("2A 06 01 02 25 51 00 00 00 00 01 00 00 00 78"));
  EXPECT_EQ(data.size(), 43U);
  EXPECT_EQ(Bytes(high.begin(), high.begin() + 14),
            hex("41 09 02 25 51 00 00 00 00 01 3F F8 00 00"));
  EXPECT_EQ(high.size(), 66U);
  EXPECT_EQ(Bytes(low.begin(), low.begin() + 15),
            hex("22 08 03 02 25 51 00 00 00 00 01 00 00 00 57"));
  EXPECT_EQ(low.size(), 35U);

  const auto v2019 = decode_with("svgui-2019", concat({data, data}));
  EXPECT_EQ(kinds(v2019), (std::vector<std::string>{"DATA", "DATA"}));
  EXPECT_EQ(v2019[0].raw, data);
  EXPECT_EQ(v2019[0].text, svgui::describe(kData));

  const Bytes map = svgui::encode_prefixed(
      svgui::Map{8, 6, std::vector<std::vector<std::int8_t>>(6, std::vector<std::int8_t>(8, 0))},
      svgui::Version::head);
  ASSERT_EQ(map.size(), 80U);  // 79 packet bytes for 8 x 6
  const Bytes head_stream = concat(
      {map, low, high, high, svgui::encode_prefixed(svgui::SetRequest{}, svgui::Version::head),
       svgui::encode_prefixed(svgui::Set{}, svgui::Version::head),
       svgui::encode_prefixed(svgui::Answer{std::nullopt, 1}, svgui::Version::head),
       svgui::encode_prefixed(svgui::Control{0.5, -0.5}, svgui::Version::head)});
  const auto head = decode_with("svgui-head", head_stream);
  EXPECT_EQ(kinds(head),
            (std::vector<std::string>{"MAP", "LOW_FREQ_DATA", "HIGH_FREQ_DATA", "HIGH_FREQ_DATA",
                                      "SET_REQUEST", "SET", "ANSWER", "CONTROL"}));
  for (const auto& f : head)
    EXPECT_TRUE(f.valid) << f.kind << ": " << f.text;
  EXPECT_EQ(head[2].raw, high);
  EXPECT_EQ(head[1].raw, low);
}

TEST(ProtocolAdapter, SvguiStreamsAreNeverReadAsUnframedPackets) {
  // A HIGH-FREQ DATA whose timestamp bytes read 02 01 02 03: unframed, that
  // is an AUTH-REPLY. Framed by its length byte it is one DATA packet,
  // however the bytes arrive.
  const svgui::HighFreqData tricky{0x02010203, 0, 0, 0, 0, 0};
  const Bytes packet = svgui::encode_prefixed(tricky, svgui::Version::head);
  ASSERT_EQ(Bytes(packet.begin(), packet.begin() + 6), hex("41 09 02 01 02 03"));
  const Bytes stream = concat({packet, packet, packet});
  for (const std::string_view profile : {"svgui-2019", "svgui-head"}) {
    auto splitter = protocol_adapter("wr8", profile)->splitter();
    std::vector<WireFrame> bytewise;
    for (const auto b : stream)
      splitter->feed(protocol::ByteView(&b, 1), bytewise);
    splitter->finish(bytewise);
    ASSERT_EQ(bytewise.size(), 3U) << profile;
    for (const auto& f : bytewise) {
      EXPECT_EQ(f.raw, packet) << profile;
      EXPECT_NE(f.kind, "AUTH_REPLY") << profile;
    }
  }
  // v2019 has no code 9: the frame is cut right and reported, not re-read.
  const auto old = decode_with("svgui-2019", packet);
  ASSERT_EQ(old.size(), 1U);
  EXPECT_FALSE(old[0].valid);
  EXPECT_THAT(old[0].text, testing::StartsWith("unknown_code"));
  // The document dialect, which has no length byte, reads the same bytes as
  // other packets entirely.
  const auto document = decode("wr8", stream);
  EXPECT_FALSE(document.size() == 3U && document[0].raw == packet);
}

TEST(ProtocolAdapter, SvguiLengthBytesThatCannotBeRightAreInvalidFrames) {
  // 0 frames nothing; 0x80 and above is a negative signed char (a body of
  // 128 bytes or more). Each is a one-byte invalid frame, and the next
  // byte is read as a length byte again.
  const Bytes reply = hex("04 02 01 02 03");
  const auto frames = decode_with("svgui-head", concat({hex("00 80 FF"), reply}));
  ASSERT_EQ(frames.size(), 4U);
  EXPECT_FALSE(frames[0].valid);
  EXPECT_EQ(frames[0].raw, hex("00"));
  EXPECT_THAT(frames[0].text, testing::StartsWith("bad_format: "));
  for (const std::size_t i : {1U, 2U}) {
    EXPECT_FALSE(frames[i].valid);
    EXPECT_EQ(frames[i].raw.size(), 1U);
    EXPECT_THAT(frames[i].text, testing::StartsWith("oversized: "));
    EXPECT_THAT(frames[i].text, testing::HasSubstr("128 bytes or more"));
  }
  EXPECT_TRUE(frames[3].valid);
  EXPECT_EQ(frames[3].raw, reply);

  // A stream of nothing but bad length bytes holds nothing.
  auto splitter = protocol_adapter("wr8", "svgui-2019")->splitter();
  std::vector<WireFrame> out;
  splitter->feed(Bytes(1000, 0x9C), out);
  EXPECT_EQ(out.size(), 1000U);
  EXPECT_EQ(splitter->buffered(), 0U);
}

TEST(ProtocolAdapter, SvguiBrokenPacketsKeepTheirNameAndTheirBytes) {
  // A LOW-FREQ DATA cut to 5 bytes by its length byte: the name rules match
  // (with '_'), the decoder's error, and the bytes with the length byte.
  const Bytes short_low = hex("05 08 03 00 00 00");
  const auto frames = decode_with("svgui-head", concat({short_low, hex("05 02 01")}));
  ASSERT_EQ(frames.size(), 2U);
  EXPECT_FALSE(frames[0].valid);
  EXPECT_EQ(frames[0].kind, "LOW_FREQ_DATA");
  EXPECT_THAT(frames[0].text, testing::StartsWith("bad_format: "));
  EXPECT_EQ(frames[0].raw, short_low);
  // The stream ended two bytes into a five-byte packet.
  EXPECT_FALSE(frames[1].valid);
  EXPECT_THAT(frames[1].text, testing::StartsWith("truncated: "));
  EXPECT_EQ(frames[1].raw, hex("05 02 01"));
  // TASK is a v2019 packet; the head programs have no code 3.
  const Bytes task = svgui::encode_prefixed(svgui::Task{7, 1, {100}}, svgui::Version::v2019);
  EXPECT_EQ(decode_with("svgui-2019", task)[0].kind, "TASK");
  EXPECT_FALSE(decode_with("svgui-head", task)[0].valid);
}

TEST(ProtocolAdapter, SvguiFieldsCountTheLengthByte) {
  const auto old = protocol_adapter("wr8", "svgui-2019");
  const auto head = protocol_adapter("wr8", "svgui-head");
  const Bytes task = svgui::encode_prefixed(svgui::Task{7, 1, {100}}, svgui::Version::v2019);
  ASSERT_EQ(task, hex("08 03 07 01 01 64 00 00 00"));  // little-endian, as the v2019 GUI writes
  EXPECT_FALSE(old->checksum_field(task));
  EXPECT_EQ(old->field(task, "length"), (ByteRange{0, 1}));
  EXPECT_EQ(old->field(task, "code"), (ByteRange{1, 2}));
  EXPECT_EQ(old->field(task, "coi"), (ByteRange{2, 3}));
  EXPECT_EQ(old->field(task, "body"), (ByteRange{2, 9}));
  EXPECT_EQ(old->field(task, "payload"), (ByteRange{2, 9}));
  EXPECT_FALSE(old->field(task, "seq"));

  const Bytes settings =
      svgui::encode_prefixed(svgui::Settings{9, {1, 2, 3, 90}}, svgui::Version::v2019);
  EXPECT_EQ(settings.size(), 19U);  // 18 packet bytes
  EXPECT_EQ(old->field(settings, "coi"), (ByteRange{2, 3}));
  const Bytes answer = svgui::encode_prefixed(svgui::Answer{9, 2}, svgui::Version::v2019);
  EXPECT_EQ(answer, hex("03 05 09 02"));
  EXPECT_EQ(old->field(answer, "coi"), (ByteRange{2, 3}));
  const Bytes data = svgui::encode_prefixed(kData, svgui::Version::v2019);
  EXPECT_FALSE(old->field(data, "coi")) << "DATA has no COI";
  EXPECT_EQ(old->field(data, "body"), (ByteRange{2, 43}));

  // The head ANSWER has no COI; nor has any head packet.
  const Bytes head_answer =
      svgui::encode_prefixed(svgui::Answer{std::nullopt, 1}, svgui::Version::head);
  EXPECT_EQ(head_answer, hex("02 05 01"));
  EXPECT_FALSE(head->field(head_answer, "coi"));
  EXPECT_EQ(head->field(head_answer, "body"), (ByteRange{2, 3}));
  // SET-REQUEST is a code and nothing else.
  const Bytes request = svgui::encode_prefixed(svgui::SetRequest{}, svgui::Version::head);
  EXPECT_EQ(request, hex("01 06"));
  EXPECT_EQ(head->field(request, "code"), (ByteRange{1, 2}));
  EXPECT_FALSE(head->field(request, "body"));
  // A bad length byte is a length and nothing more.
  EXPECT_EQ(head->field(hex("9C"), "length"), (ByteRange{0, 1}));
  EXPECT_FALSE(head->field(hex("9C"), "code"));
  EXPECT_FALSE(head->field(Bytes{}, "length"));

  EXPECT_THAT(old->field_names(),
              testing::UnorderedElementsAre("length", "code", "payload", "body", "coi"));
  EXPECT_THAT(head->field_names(),
              testing::UnorderedElementsAre("length", "code", "payload", "body"));
}

TEST(ProtocolAdapter, RawMakesEachWriteOneFrameAndHoldsNothing) {
  auto splitter = protocol_adapter("raw")->splitter();
  std::vector<WireFrame> frames;
  splitter->feed(to_bytes("LOGI:SP"), frames);
  EXPECT_EQ(splitter->buffered(), 0U);
  splitter->feed(to_bytes(":050"), frames);
  ASSERT_EQ(frames.size(), 2U);
  EXPECT_EQ(frames[0].raw, to_bytes("LOGI:SP"));
  EXPECT_EQ(frames[1].raw, to_bytes(":050"));
}

}  // namespace
}  // namespace hil::link
