// The Leka client core on its own, in exact virtual time: the checked
// builder, frames from the codec, splitting at command boundaries, pacing
// against the 128-byte serial buffer, info replies and timeouts, the log.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "client/leka/comm_log.hpp"
#include "client/leka/core.hpp"

namespace hil::client::leka {
namespace {

using link::milliseconds;

Time at_ms(int ms) {
  return Time(milliseconds(ms));
}

Bytes bytes_of(std::string_view s) {
  return Bytes(s.begin(), s.end());
}

proto::CommandGroup decode_group(const Bytes& frame) {
  auto item = proto::decode_frame(frame);
  auto* f = std::get_if<protocol::Frame<proto::Message>>(&item);
  EXPECT_NE(f, nullptr);
  return f ? f->message : proto::CommandGroup{};
}

/// 60 belt.single commands of 5 bytes: a 300-byte command group.
GroupBuilder burst() {
  GroupBuilder b;
  for (int i = 0; i < 60; ++i)
    b.belt_single(i % 20, {static_cast<std::uint8_t>(i), 0, 0});
  return b;
}

TEST(LekaBuilder, ValidChainBuildsTheCommandsInOrder) {
  GroupBuilder b;
  b.ear_all({255, 0, 0}).belt_range(2, 5, {0, 0, 255}).motor_duo(0, 100, 1, 100).guidance(0x41);
  ASSERT_TRUE(b.result().ok());
  ASSERT_EQ(b.group().commands.size(), 4u);
  EXPECT_EQ(b.group().commands[2], proto::Command(proto::MotorDuo{0, 100, 1, 100}));
}

TEST(LekaBuilder, AWrongValueIsNamedAndLeftOut) {
  struct Case {
    std::function<void(GroupBuilder&)> add;
    std::string field;
  };
  const std::vector<Case> cases = {
      {[](GroupBuilder& b) { b.ear_single(2, {}); }, "led.ear.single led"},
      {[](GroupBuilder& b) { b.belt_single(20, {}); }, "led.belt.single led"},
      {[](GroupBuilder& b) { b.belt_range(5, 3, {}); }, "led.belt.range last"},
      {[](GroupBuilder& b) { b.belt_range(-1, 3, {}); }, "led.belt.range first"},
      {[](GroupBuilder& b) { b.motor_all(2, 10); }, "motor.all direction"},
      {[](GroupBuilder& b) { b.motor_all(0, 256); }, "motor.all speed"},
      {[](GroupBuilder& b) { b.motor_duo(0, 1, 0, -1); }, "motor.duo right_speed"},
      {[](GroupBuilder& b) { b.motor_left(0, 300); }, "motor.left speed"},
      {[](GroupBuilder& b) { b.motor_right(3, 0); }, "motor.right spin"},
      {[](GroupBuilder& b) { b.motivator(0x56); }, "motivator id"},
      {[](GroupBuilder& b) { b.guidance(0x40); }, "guidance id"},
  };
  for (const auto& c : cases) {
    GroupBuilder b;
    b.stop_led();
    c.add(b);
    b.stop_motor();
    EXPECT_EQ(b.result().error, BuildError::out_of_range) << c.field;
    EXPECT_EQ(b.result().field, c.field);
    EXPECT_EQ(b.group().commands.size(), 2u) << c.field;
  }
  EXPECT_EQ(GroupBuilder{}.result().error, BuildError::group_empty);
}

TEST(LekaBuilder, ACoreRefusesABuilderWithAnError) {
  LekaClientCore core;
  core.on_connected(at_ms(0));
  GroupBuilder b;
  b.motor_all(0, 999);
  EXPECT_EQ(core.send(at_ms(0), b).field, "motor.all speed");
  EXPECT_TRUE(core.take_actions().empty());
}

TEST(LekaFrames, OneBeltLedIsTheSeedFrame) {
  LekaClientCore core;
  core.on_connected(at_ms(0));
  ASSERT_TRUE(core.send(at_ms(0), GroupBuilder{}.belt_single(0, {255, 0, 0})).ok());
  auto actions = core.take_actions();
  ASSERT_EQ(actions.size(), 1u);
  EXPECT_EQ(actions[0].bytes,
            (Bytes{0x2A, 0x2B, 0x2C, 0x2D, 0x05, 0x15, 0x00, 0xFF, 0x00, 0x00, 0x41}));
}

// Profile comspecs-v3: the spec's YAML ids and the 8-bit checksum over
// length and group; the vector is MMyster/Leka-Command-Generator's demo.
TEST(LekaFrames, ComspecsProfileSendsTheYamlIdsAndTheirChecksum) {
  ClientConfig config;
  config.dialect = proto::Dialect::comspecs_v3;
  LekaClientCore core(config);
  core.on_connected(at_ms(0));
  ASSERT_TRUE(core.send(at_ms(0), GroupBuilder{}.belt_single(0x12, {100, 150, 200})).ok());
  core.info(at_ms(0));
  std::vector<SendFrame> actions = core.take_actions();
  for (int ms = 1; ms <= 20 && actions.size() < 2; ++ms) {
    core.on_timer(at_ms(ms));
    for (auto& a : core.take_actions())
      actions.push_back(std::move(a));
  }
  ASSERT_EQ(actions.size(), 2u);
  EXPECT_EQ(protocol::to_hex(actions[0].bytes), "2A 2B 2C 2D 05 16 12 64 96 C8 77");
  EXPECT_EQ(protocol::to_hex(actions[1].bytes), "2A 2B 2C 2D 01 70 F0");
  // The ear range exists only there; the README's profile refuses it.
  EXPECT_TRUE(core.send(at_ms(30), GroupBuilder{}.ear_range(0, 1, {255, 0, 0})).ok());
  LekaClientCore readme;
  readme.on_connected(at_ms(0));
  const BuildResult refused = readme.send(at_ms(0), GroupBuilder{}.ear_range(0, 1, {255, 0, 0}));
  EXPECT_EQ(refused.error, BuildError::not_in_profile);
  EXPECT_EQ(refused.field, "led.ear.range");
  EXPECT_TRUE(readme.take_actions().empty());
}

TEST(LekaFrames, ALargeGroupIsSplitAtCommandBoundaries) {
  // 58 group bytes per frame: 11 five-byte commands, then the rest.
  GroupBuilder b = burst();
  const auto frames = split_frames(b.group(), 58);
  ASSERT_EQ(frames.size(), 6u);
  proto::CommandGroup joined;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].size(), i < 5 ? 61u : 31u);
    auto g = decode_group(frames[i]);
    joined.commands.insert(joined.commands.end(), g.commands.begin(), g.commands.end());
  }
  EXPECT_EQ(joined, b.group());
  // Mixed sizes: a 5-byte command that would cross the bound starts a frame.
  GroupBuilder mixed;
  mixed.motor_duo(0, 1, 0, 1).belt_range(0, 3, {}).info();
  const auto parts = split_frames(mixed.group(), 9);
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(decode_group(parts[0]).commands.size(), 1u);
  EXPECT_EQ(decode_group(parts[1]).commands.size(), 2u);
}

TEST(LekaPacing, A300ByteBurstGoesOutOneFramePerLoopPeriod) {
  LekaClientCore core;
  core.on_connected(at_ms(0));
  ASSERT_TRUE(core.send(at_ms(0), burst()).ok());
  std::vector<std::pair<int, std::size_t>> sent;
  auto collect = [&](Time now) {
    for (auto& a : core.take_actions())
      sent.push_back({static_cast<int>(now.count() / 1'000'000), a.bytes.size()});
  };
  collect(at_ms(0));
  EXPECT_EQ(core.next_wakeup(), at_ms(10));
  // An early wakeup sends nothing.
  core.on_timer(at_ms(9));
  collect(at_ms(9));
  while (auto due = core.next_wakeup()) {
    core.on_timer(*due);
    collect(*due);
  }
  const std::vector<std::pair<int, std::size_t>> expected = {{0, 61},  {10, 61}, {20, 61},
                                                             {30, 61}, {40, 61}, {50, 31}};
  EXPECT_EQ(sent, expected);
}

TEST(LekaPacing, SmallFramesShareAPeriodUpTo64Bytes) {
  LekaClientCore core;
  core.on_connected(at_ms(0));
  // Nine 7-byte frames: 63 bytes fit in one period, the ninth waits.
  for (int i = 0; i < 9; ++i)
    core.send(at_ms(0), GroupBuilder{}.stop_led());
  EXPECT_EQ(core.take_actions().size(), 9u);
  core.send(at_ms(3), GroupBuilder{}.stop_led());
  EXPECT_TRUE(core.take_actions().empty());
  EXPECT_EQ(core.next_wakeup(), at_ms(10));
  core.on_timer(at_ms(10));
  EXPECT_EQ(core.take_actions().size(), 1u);
}

TEST(LekaPacing, UnpacedSendsEverythingAtOnce) {
  LekaClientCore core({.paced = false});
  core.on_connected(at_ms(0));
  core.send(at_ms(0), burst());
  EXPECT_EQ(core.take_actions().size(), 6u);
  EXPECT_EQ(core.next_wakeup(), std::nullopt);
}

TEST(LekaPacing, NothingGoesOutBeforeThePortOpens) {
  LekaClientCore core;
  core.send(at_ms(0), GroupBuilder{}.stop_robot());
  EXPECT_TRUE(core.take_actions().empty());
  core.on_connected(at_ms(5));
  EXPECT_EQ(core.take_actions().size(), 1u);
}

TEST(LekaInfo, TheLineIsParsedIntoFields) {
  auto reply = parse_info_line("LEKA name=leka firmware=1.0.0 buffer=128 state=ok\r\n");
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->name, "leka");
  EXPECT_EQ(reply->firmware, "1.0.0");
  EXPECT_EQ(reply->buffer_bytes, 128);
  EXPECT_EQ(reply->state, "ok");
  EXPECT_EQ(reply->fields.size(), 4u);
  EXPECT_FALSE(parse_info_line("HELLO name=x").has_value());
  EXPECT_FALSE(parse_info_line("LEKA name").has_value());
}

TEST(LekaInfo, NoiseBeforeTheReplyOnItsLineIsSkipped) {
  // Garbage bytes that reached the line before the robot's reply.
  auto reply = parse_info_line("\x9d\x01zLEKA~LEKA name=leka firmware=1.0.0 buffer=128 state=ok");
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->name, "leka");
  EXPECT_EQ(reply->buffer_bytes, 128);
  EXPECT_EQ(reply->fields.size(), 4u);
  EXPECT_FALSE(parse_info_line("\x9d\x01LEKAname=x").has_value());
}

TEST(LekaInfo, AReplyInTimeEndsTheRequest) {
  LekaClientCore core;
  core.on_connected(at_ms(0));
  const RequestId id = core.info(at_ms(0));
  auto actions = core.take_actions();
  ASSERT_EQ(actions.size(), 1u);
  EXPECT_EQ(actions[0].bytes, (Bytes{0x2A, 0x2B, 0x2C, 0x2D, 0x01, 0x70, 0x70}));
  EXPECT_EQ(core.next_wakeup(), at_ms(200));
  core.on_bytes(at_ms(10), bytes_of("LEKA name=leka firm"));
  core.on_bytes(at_ms(11), bytes_of("ware=1.0.0 buffer=128 state=fault\r\n"));
  auto events = core.take_events();
  ASSERT_EQ(events.size(), 2u);
  auto* done = std::get_if<InfoDone>(&events[1]);
  ASSERT_NE(done, nullptr);
  EXPECT_EQ(done->id, id);
  EXPECT_EQ(done->result.status, InfoStatus::ok);
  EXPECT_EQ(done->result.reply->state, "fault");
  EXPECT_EQ(core.next_wakeup(), std::nullopt);
}

TEST(LekaInfo, NoReplyTimesOutExactly200msAfterTheFrameWentOut) {
  LekaClientCore core;
  core.on_connected(at_ms(0));
  core.send(at_ms(0), burst());  // the info waits behind five paced frames
  const RequestId id = core.info(at_ms(0));
  std::optional<Time> info_sent;
  std::optional<Time> timed_out;
  core.take_actions();
  while (auto due = core.next_wakeup()) {
    core.on_timer(*due);
    for (auto& a : core.take_actions())
      if (a.bytes.size() == 7) info_sent = *due;
    for (auto& e : core.take_events())
      if (auto* d = std::get_if<InfoDone>(&e); d && d->id == id) {
        EXPECT_EQ(d->result.status, InfoStatus::timeout);
        timed_out = *due;
      }
  }
  // The 31-byte last frame at 50 ms leaves room for the 7-byte info then.
  EXPECT_EQ(info_sent, at_ms(50));
  EXPECT_EQ(timed_out, at_ms(250));
}

TEST(LekaInfo, ClosingThePortEndsWaitingRequests) {
  LekaClientCore core;
  core.on_connected(at_ms(0));
  const RequestId id = core.info(at_ms(0));
  core.on_closed(at_ms(5));
  auto events = core.take_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(std::get<InfoDone>(events[0]).id, id);
  EXPECT_EQ(std::get<InfoDone>(events[0]).result.status, InfoStatus::closed);
}

TEST(LekaCommLog, ExportsTextCsvAndNdjson) {
  CommLog log;
  log.add({LogKind::tx, 1000, Bytes{0x2A, 0x01}, "info"});
  log.add({LogKind::rx, 2000, bytes_of("LEKA a=\"b\""), "LEKA a=\"b\""});
  EXPECT_EQ(log.to_string(LogFormat::txt),
            "1000 TX info [2A 01]\n2000 RX LEKA a=\"b\" [4C 45 4B 41 20 61 3D 22 62 22]\n");
  EXPECT_EQ(log.to_string(LogFormat::csv),
            "utc_us,direction,note,hex\n1000,TX,info,2A 01\n"
            "2000,RX,\"LEKA a=\"\"b\"\"\",4C 45 4B 41 20 61 3D 22 62 22\n");
  EXPECT_EQ(log.to_string(LogFormat::ndjson),
            "{\"utc_us\":1000,\"direction\":\"TX\",\"note\":\"info\",\"hex\":\"2A 01\"}\n"
            "{\"utc_us\":2000,\"direction\":\"RX\",\"note\":\"LEKA a=\\\"b\\\"\","
            "\"hex\":\"4C 45 4B 41 20 61 3D 22 62 22\"}\n");
}

}  // namespace
}  // namespace hil::client::leka
