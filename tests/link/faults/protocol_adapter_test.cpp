#include "link/protocol_adapter.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>

#include "protocol/arduino/codec.hpp"
#include "protocol/common/car_profile.hpp"
#include "protocol/leka/codec.hpp"
#include "protocol/logi/codec.hpp"
#include "protocol/wr8/codec.hpp"
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
