// The Leka probe in each profile: its shape (unique names, connect first,
// stop last, under 40 s), what every exchange's bytes decode to with the
// profile's own protocol adapter, and that it drives the robot safely.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "conform/probe.hpp"
#include "link/protocol_adapter.hpp"
#include "protocol/leka/codec.hpp"

namespace hil::conform {
namespace {

namespace leka = protocol::leka;
using std::chrono::milliseconds;

const std::vector<std::string> kProfiles = {"readme", "comspecs-v3"};

// What an exchange's bytes are, in the order they come out of the
// profile's splitter: a valid frame as its kind (the first command's
// name), a refused one as "!" and the error kind. `lines`: the info
// commands in its valid frames, one answer line each.
struct Expected {
  ExchangeKind kind;
  std::vector<std::string> items;
  std::size_t lines = 0;
  bool comspecs_only = false;
};

std::map<std::string, Expected> expected_exchanges() {
  using K = ExchangeKind;
  const std::vector<std::string> none;
  return {
      {"connect", {K::connect, none, 0}},
      {"info", {K::command, {"info"}, 1}},
      {"info-twice", {K::command, {"info"}, 2}},
      {"stop-led", {K::command, {"stop.led"}, 1}},
      {"stop-motor", {K::command, {"stop.motor"}, 1}},
      {"stop-robot", {K::command, {"stop.robot"}, 1}},
      {"ear-all", {K::command, {"led.ear.all"}, 1}},
      {"ear-all-max", {K::boundary, {"led.ear.all"}, 1}},
      {"ear-all-min", {K::boundary, {"led.ear.all"}, 1}},
      {"ear-single", {K::command, {"led.ear.single"}, 1}},
      {"ear-single-id-1", {K::boundary, {"led.ear.single"}, 1}},
      {"ear-single-id-2", {K::error, {"!bad_value"}, 0}},
      {"ear-range", {K::command, {"led.ear.range"}, 1, true}},
      {"ear-range-one", {K::boundary, {"led.ear.range"}, 1, true}},
      {"ear-range-last-2", {K::error, {"!bad_value"}, 0, true}},
      {"ear-range-reversed", {K::error, {"!bad_value"}, 0, true}},
      {"belt-all", {K::command, {"led.belt.all"}, 1}},
      {"belt-all-max", {K::boundary, {"led.belt.all"}, 1}},
      {"belt-all-min", {K::boundary, {"led.belt.all"}, 1}},
      {"belt-single", {K::command, {"led.belt.single"}, 1}},
      {"belt-single-id-19", {K::boundary, {"led.belt.single"}, 1}},
      {"belt-single-id-20", {K::error, {"!bad_value"}, 0}},
      {"belt-single-id-0x19", {K::error, {"!bad_value"}, 0}},
      {"belt-range", {K::command, {"led.belt.range"}, 1}},
      {"belt-range-full", {K::boundary, {"led.belt.range"}, 1}},
      {"belt-range-one", {K::boundary, {"led.belt.range"}, 1}},
      {"belt-range-last-20", {K::error, {"!bad_value"}, 0}},
      {"belt-range-reversed", {K::error, {"!bad_value"}, 0}},
      {"motor-all-forward", {K::command, {"motor.all"}, 1}},
      {"motor-all-backward", {K::command, {"motor.all"}, 1}},
      {"motor-all-zero", {K::boundary, {"motor.all"}, 1}},
      {"motor-all-max", {K::boundary, {"motor.all"}, 1}},
      {"motor-all-direction-2", {K::error, {"!bad_value"}, 0}},
      {"motor-duo", {K::command, {"motor.duo"}, 1}},
      {"motor-duo-zero", {K::boundary, {"motor.duo"}, 1}},
      {"motor-duo-max", {K::boundary, {"motor.duo"}, 1}},
      {"motor-duo-left-spin-2", {K::error, {"!bad_value"}, 0}},
      {"motor-duo-right-spin-2", {K::error, {"!bad_value"}, 0}},
      {"motor-left", {K::command, {"motor.left"}, 1}},
      {"motor-left-zero", {K::boundary, {"motor.left"}, 1}},
      {"motor-left-max", {K::boundary, {"motor.left"}, 1}},
      {"motor-left-spin-2", {K::error, {"!bad_value"}, 0}},
      {"motor-right", {K::command, {"motor.right"}, 1}},
      {"motor-right-zero", {K::boundary, {"motor.right"}, 1}},
      {"motor-right-max", {K::boundary, {"motor.right"}, 1}},
      {"motor-right-spin-2", {K::error, {"!bad_value"}, 0}},
      {"motivator", {K::command, {"motivator"}, 1}},
      {"motivator-0x51", {K::boundary, {"motivator"}, 1}},
      {"motivator-0x55", {K::boundary, {"motivator"}, 1}},
      {"motivator-0x50", {K::error, {"!bad_value"}, 0}},
      {"motivator-0x56", {K::error, {"!bad_value"}, 0}},
      {"guidance", {K::command, {"guidance"}, 1}},
      {"guidance-0x41", {K::boundary, {"guidance"}, 1}},
      {"guidance-0x4f", {K::boundary, {"guidance"}, 1}},
      {"guidance-0x40", {K::error, {"!bad_value"}, 0}},
      {"guidance-0x50", {K::error, {"!bad_value"}, 0}},
      {"group-122", {K::boundary, {"led.belt.single"}, 1}},
      // The header goes as oversized; the 124 bytes after it hold no start
      // sequence and come out as garbage.
      {"group-123", {K::error, {"!oversized", "!garbage"}, 0}},
      {"length-0", {K::error, {"!bad_format", "!garbage"}, 0}},
      {"bad-checksum", {K::error, {"!bad_checksum"}, 0}},
      {"other-profile-checksum", {K::error, {"!bad_checksum"}, 0}},
      {"command-cut", {K::error, {"!bad_format"}, 0}},
      {"unknown-id", {K::error, {"!unknown_code"}, 0}},
      {"bad-value-after-info", {K::error, {"!bad_value"}, 0}},
      {"garbage", {K::error, {"!garbage"}, 0}},
      {"garbage-between-frames", {K::framing, {"info", "!garbage", "led.ear.all"}, 2}},
      {"split-bytes", {K::framing, {"led.belt.all"}, 1}},
      {"split-pause", {K::framing, {"info"}, 1}},
      {"two-frames", {K::framing, {"info", "led.belt.all"}, 2}},
      {"telemetry", {K::telemetry, none, 0}},
      {"partial-before-reconnect", {K::framing, {"!truncated"}, 0}},
      {"reconnect", {K::connect, none, 0}},
      {"info-after-reconnect", {K::command, {"info"}, 1}},
      {"stop", {K::stop, {"stop.robot"}, 1}},
  };
}

leka::DecoderOptions options_of(std::string_view profile, bool lenient = false) {
  leka::DecoderOptions options;
  options.dialect = leka::dialect_named(profile);
  options.accept_out_of_range = lenient;
  return options;
}

Bytes all_bytes(const Exchange& exchange) {
  Bytes bytes;
  for (const auto& w : exchange.writes)
    bytes.insert(bytes.end(), w.bytes.begin(), w.bytes.end());
  return bytes;
}

// The exchange's writes, each fed on its own to the profile's splitter.
std::vector<link::WireFrame> split(std::string_view profile, const Exchange& exchange) {
  auto splitter = link::protocol_adapter("leka", profile)->splitter();
  std::vector<link::WireFrame> frames;
  for (const auto& w : exchange.writes)
    splitter->feed(w.bytes, frames);
  splitter->finish(frames);
  return frames;
}

std::vector<std::string> items_of(const std::vector<link::WireFrame>& frames) {
  std::vector<std::string> items;
  for (const auto& f : frames)
    items.push_back(f.valid ? f.kind : "!" + f.text.substr(0, f.text.find(':')));
  return items;
}

// The commands of the exchange's frames that decode (with out-of-range
// values accepted when `lenient`: what a robot that does not check ranges
// would run).
std::vector<std::vector<leka::Command>> groups_of(std::string_view profile,
                                                  const Exchange& exchange, bool lenient) {
  leka::Decoder decoder(options_of(profile, lenient));
  std::vector<leka::Item> items;
  decoder.feed(all_bytes(exchange), items);
  decoder.finish(items);
  std::vector<std::vector<leka::Command>> groups;
  for (const auto& item : items) {
    if (const auto* f = std::get_if<protocol::Frame<leka::Message>>(&item))
      groups.push_back(f->message.commands);
  }
  return groups;
}

const Exchange& exchange_named(const Probe& probe, std::string_view name) {
  for (const auto& e : probe.exchanges) {
    if (e.name == name) return e;
  }
  throw std::out_of_range("no exchange " + std::string(name));
}

class LekaProbe : public ::testing::TestWithParam<std::string> {
 protected:
  const std::string& profile() const { return GetParam(); }
  Probe probe() const { return make_probe(mocks::CarKind::leka, profile()); }
};

TEST_P(LekaProbe, HasUniqueNamesStartsWithConnectAndEndsWithStop) {
  const Probe p = probe();
  EXPECT_EQ(p.version, "leka-probe/1");
  EXPECT_EQ(p.car, mocks::CarKind::leka);
  EXPECT_EQ(p.profile, profile());
  ASSERT_GE(p.exchanges.size(), 2U);
  std::set<std::string> names;
  for (const auto& e : p.exchanges)
    EXPECT_TRUE(names.insert(e.name).second) << e.name;
  EXPECT_EQ(p.exchanges.front().name, "connect");
  EXPECT_EQ(p.exchanges.front().kind, ExchangeKind::connect);
  EXPECT_TRUE(p.exchanges.front().writes.empty());
  EXPECT_EQ(p.exchanges.back().kind, ExchangeKind::stop);
  // The robot sends nothing on its own.
  EXPECT_TRUE(p.telemetry_kinds.empty());
}

TEST_P(LekaProbe, RunsUnderFortySeconds) {
  const Probe p = probe();
  EXPECT_LT(p.duration(), std::chrono::seconds(40));
  EXPECT_GT(p.duration(), std::chrono::seconds(10));
}

TEST_P(LekaProbe, HasExactlyTheExchangesOfItsProfileWithTheirKinds) {
  const Probe p = probe();
  const auto expected = expected_exchanges();
  std::set<std::string> wanted;
  for (const auto& [name, e] : expected) {
    if (!e.comspecs_only || profile() == "comspecs-v3") wanted.insert(name);
  }
  std::set<std::string> got;
  for (const auto& e : p.exchanges) {
    got.insert(e.name);
    const auto it = expected.find(e.name);
    ASSERT_NE(it, expected.end()) << e.name;
    EXPECT_EQ(e.kind, it->second.kind) << e.name;
  }
  EXPECT_EQ(got, wanted);
}

TEST_P(LekaProbe, EveryExchangesBytesSplitAsItSays) {
  const auto expected = expected_exchanges();
  for (const auto& e : probe().exchanges) {
    const auto& want = expected.at(e.name);
    const auto frames = split(profile(), e);
    EXPECT_EQ(items_of(frames), want.items) << e.name << ": " << e.what;
    // Command, boundary and stop exchanges hold only valid frames (at
    // least one); error exchanges none at all.
    const auto valid = std::count_if(frames.begin(), frames.end(),
                                     [](const link::WireFrame& f) { return f.valid; });
    switch (e.kind) {
      case ExchangeKind::command:
      case ExchangeKind::boundary:
      case ExchangeKind::stop:
        EXPECT_GT(valid, 0) << e.name;
        EXPECT_EQ(static_cast<std::size_t>(valid), frames.size()) << e.name;
        break;
      case ExchangeKind::error:
        EXPECT_EQ(valid, 0) << e.name;
        EXPECT_FALSE(frames.empty()) << e.name;
        break;
      default:
        break;
    }
  }
}

TEST_P(LekaProbe, EachValidFrameEndsWithTheInfosThatMakeTheRobotAnswer) {
  for (const auto& e : probe().exchanges) {
    std::size_t infos = 0;
    for (const auto& group : groups_of(profile(), e, false)) {
      ASSERT_FALSE(group.empty()) << e.name;
      EXPECT_TRUE(std::holds_alternative<leka::Info>(group.back())) << e.name;
      infos +=
          static_cast<std::size_t>(std::count_if(group.begin(), group.end(), [](const auto& c) {
            return std::holds_alternative<leka::Info>(c);
          }));
    }
    EXPECT_EQ(infos, expected_exchanges().at(e.name).lines) << e.name;
  }
}

TEST_P(LekaProbe, NoValidFrameIsValidInTheOtherProfile) {
  // So that every exchange the robot answers tells the two profiles apart
  // (the checksums agree for about one group in 256).
  const std::string other = profile() == "readme" ? "comspecs-v3" : "readme";
  for (const auto& e : probe().exchanges) {
    const auto here = groups_of(profile(), e, false);
    const auto there = groups_of(other, e, false);
    if (e.name == "other-profile-checksum") {
      EXPECT_TRUE(here.empty());
      EXPECT_EQ(there.size(), 1U);
    } else {
      EXPECT_TRUE(there.empty()) << e.name << " is valid in " << other << " too";
    }
  }
}

TEST_P(LekaProbe, ListensLongEnoughForTheLongestLineAtTheRobotsBaud) {
  // 128 bytes at 115,200 baud take 11.1 ms; the frame written, a 10 ms
  // loop pass and 200 ms of margin come on top.
  for (const auto& e : probe().exchanges) {
    const auto written = all_bytes(e).size();
    const auto lines = std::max<std::size_t>(expected_exchanges().at(e.name).lines, 1);
    const Duration needed =
        std::chrono::microseconds(87) * static_cast<long>(written + 128 * lines) +
        milliseconds(210);
    EXPECT_GE(e.listen, needed) << e.name;
    EXPECT_FALSE(e.physical) << e.name << ": the info line carries nothing from the world";
  }
  EXPECT_GE(exchange_named(probe(), "telemetry").listen, std::chrono::seconds(1));
}

TEST_P(LekaProbe, ErrorFramesAreWhatTheySay) {
  const Probe p = probe();
  const auto dialect = leka::dialect_named(profile());
  const auto other =
      dialect == leka::Dialect::readme ? leka::Dialect::comspecs_v3 : leka::Dialect::readme;
  const Bytes info = leka::encode({{leka::Info{}}}, {}, dialect);

  // The bad checksum is the info frame with only its checksum changed.
  const Bytes bad = all_bytes(exchange_named(p, "bad-checksum"));
  ASSERT_EQ(bad.size(), info.size());
  EXPECT_TRUE(std::equal(info.begin(), info.end() - 1, bad.begin()));
  EXPECT_NE(bad.back(), info.back());

  // The other profile's info frame is valid there, and differs only in its
  // checksum.
  const Bytes foreign = all_bytes(exchange_named(p, "other-profile-checksum"));
  const auto item = leka::decode_frame(foreign, [&] {
    leka::DecoderOptions o;
    o.dialect = other;
    return o;
  }());
  const auto* frame = std::get_if<protocol::Frame<leka::Message>>(&item);
  ASSERT_NE(frame, nullptr);
  EXPECT_EQ(frame->message, (leka::CommandGroup{{leka::Info{}}}));
  EXPECT_TRUE(std::equal(info.begin(), info.end() - 1, foreign.begin()));

  // The oversized frame announces 123 group bytes; length 0 announces none.
  EXPECT_EQ(all_bytes(exchange_named(p, "group-122"))[4], 122);
  EXPECT_EQ(all_bytes(exchange_named(p, "group-122")).size(), leka::kMaxFrameBytes);
  EXPECT_EQ(all_bytes(exchange_named(p, "group-123"))[4], 123);
  EXPECT_EQ(all_bytes(exchange_named(p, "length-0"))[4], 0);

  // The unknown id is named by the decoder.
  const auto unknown = split(profile(), exchange_named(p, "unknown-id"));
  ASSERT_EQ(unknown.size(), 1U);
  EXPECT_EQ(unknown.front().kind, "0x99") << unknown.front().text;

  // Garbage holds no start sequence.
  const Bytes garbage = all_bytes(exchange_named(p, "garbage"));
  EXPECT_EQ(std::search(garbage.begin(), garbage.end(), leka::kStartSequence.begin(),
                        leka::kStartSequence.end()),
            garbage.end());

  // The partial frame is a valid frame without its last byte.
  Bytes partial = all_bytes(exchange_named(p, "partial-before-reconnect"));
  partial.push_back(leka::checksum(
      protocol::ByteView(partial).subspan(leka::kHeaderBytes, partial.size() - leka::kHeaderBytes),
      dialect));
  EXPECT_TRUE(std::holds_alternative<protocol::Frame<leka::Message>>(
      leka::decode_frame(partial, options_of(profile()))));
}

TEST_P(LekaProbe, SplitExchangesWriteOneByteOrOneHalfAtATime) {
  const Probe p = probe();
  const auto& bytewise = exchange_named(p, "split-bytes");
  ASSERT_GT(bytewise.writes.size(), 7U);
  for (std::size_t i = 0; i < bytewise.writes.size(); ++i) {
    EXPECT_EQ(bytewise.writes[i].bytes.size(), 1U);
    EXPECT_EQ(bytewise.writes[i].after, i == 0 ? Duration{0} : milliseconds(3));
  }
  const auto& pause = exchange_named(p, "split-pause");
  ASSERT_EQ(pause.writes.size(), 2U);
  EXPECT_EQ(pause.writes[1].after, milliseconds(100));
  for (const char* joined : {"two-frames", "garbage-between-frames"})
    EXPECT_EQ(exchange_named(p, joined).writes.size(), 1U) << joined;
}

// The wheels and behaviours as a robot that runs every frame it can
// parse, out-of-range values included, would have them. A behaviour is
// taken to play until a stop command, whatever else comes.
struct Motion {
  std::uint8_t left = 0;
  std::uint8_t right = 0;
  bool behaviour = false;
  bool moving() const { return left > 0 || right > 0 || behaviour; }

  void run(const leka::Command& c) {
    if (const auto* m = std::get_if<leka::MotorAll>(&c)) left = right = m->speed;
    if (const auto* m = std::get_if<leka::MotorDuo>(&c)) {
      left = m->left_speed;
      right = m->right_speed;
    }
    if (const auto* m = std::get_if<leka::MotorLeft>(&c)) left = m->speed;
    if (const auto* m = std::get_if<leka::MotorRight>(&c)) right = m->speed;
    if (std::holds_alternative<leka::Motivator>(c) || std::holds_alternative<leka::Guidance>(c))
      behaviour = true;
    if (std::holds_alternative<leka::StopMotor>(c) || std::holds_alternative<leka::StopRobot>(c))
      *this = Motion{};
  }
};

TEST_P(LekaProbe, LeavesTheRobotMovingSlowlyAndNeverForLong) {
  const Probe p = probe();
  Motion motion;
  int moving_exchanges = 0;  // in a row
  for (const auto& e : p.exchanges) {
    for (const auto& group : groups_of(profile(), e, true)) {
      for (const auto& c : group)
        motion.run(c);
      // What the robot does until the next frame: a speed over 60 never
      // outlives its own frame.
      EXPECT_LE(int{std::max(motion.left, motion.right)}, 60) << e.name;
    }
    moving_exchanges = motion.moving() ? moving_exchanges + 1 : 0;
    EXPECT_LE(moving_exchanges, 2) << e.name << ": the robot was left moving too long";
  }
  EXPECT_FALSE(motion.moving()) << "the probe ends with the robot moving";
  const auto last = groups_of(profile(), p.exchanges.back(), false);
  ASSERT_EQ(last.size(), 1U);
  EXPECT_TRUE(std::holds_alternative<leka::StopRobot>(last.front().front()));
}

INSTANTIATE_TEST_SUITE_P(Profiles, LekaProbe, ::testing::ValuesIn(kProfiles), [](const auto& info) {
  std::string name = info.param;
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
});

}  // namespace
}  // namespace hil::conform
