// Mock cars in each of their profiles (hil profiles).
// LOGI (docs/protocols/logi.md, "Profiles"): firmware reads each hand-over
// as the STM32 parser does, guide reads the stream from the first header to
// the first '#'; the frames where the two rules differ, one by one.
// Leka (docs/protocols/leka.md, "Profiles"): comspecs-v3 runs the frame
// MMyster/Leka-Command-Generator documents (belt single LED 0x12, RGB 100
// 150 200) and answers info framed its way; readme refuses that frame on its
// checksum; both keep the belt at LED ids 0..19.

#include <gtest/gtest.h>

#include <memory>

#include "link/protocol_adapter.hpp"
#include "mocks/leka.hpp"
#include "mocks/logi.hpp"
#include "protocol/leka/codec.hpp"
#include "protocol/logi/codec.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"
#include "tests/support/hex.hpp"

namespace hil::mocks {
namespace {

namespace leka = protocol::leka;
using hil::test::hex;
using leka::Dialect;
using leka::Rgb;
using link::milliseconds;
using protocol::Bytes;

// ------------------------------------------------------------------ LOGI

namespace logi = protocol::logi;

// Each write reaches the car as one delivery (one hand-over), exactly as
// written: no frame-aware link in front to hold or cut frames.
struct LogiBench {
  explicit LogiBench(logi::Dialect dialect)
      : car(
            sim::logi_car(),
            [dialect](sim::World& w, sim::Vehicle& v) {
              LogiConfig config;
              config.dialect = dialect;
              return std::make_unique<LogiFirmware>(w, v, config);
            },
            [] {
              ServerOptions options;
              options.protocol = link::protocol_adapter("raw");
              return options;
            }()),
        client(car.connect()) {}

  /// Writes each piece as its own delivery; returns the feedback frames the
  /// car sent, space-separated ("FB:SP:1 FB:MD:1"), STAT left out.
  std::string feedback(std::initializer_list<std::string_view> pieces) {
    for (const auto piece : pieces) {
      client->write(piece);
      car.run_for(link::Duration::zero());
    }
    std::vector<logi::Item> items;
    logi::Decoder decoder;
    decoder.feed(client->take(), items);
    std::string out;
    for (const auto& item : items) {
      const auto* f = std::get_if<protocol::Frame<logi::Message>>(&item);
      if (f == nullptr || !std::holds_alternative<logi::Feedback>(f->message)) continue;
      out += (out.empty() ? "" : " ") + logi::payload_of(f->message);
    }
    return out;
  }

  test::VirtualCar<LogiFirmware> car;
  std::shared_ptr<test::ClientEnd> client;
};

// Where "a frame runs from the first LOGI: to the first '#'" and the
// firmware's parser (a hand-over of 10 bytes or more, ending in '#', the
// checksum field after the last ':', the sum from index 0) disagree.
TEST(LogiProfiles, WhereTheStreamRuleAndTheFirmwareDisagreeTheMockSidesWithTheFirmware) {
  // GS with a '#' inside its argument, its checksum over all of LOGI:GS:0#1.
  const std::string hash_inside = logi::frame_text("GS:0#1");
  struct Case {
    std::string what;
    std::vector<std::string> pieces;
    std::string firmware;  // what the real car answers
    std::string guide;     // what the stream rule makes of it
  };
  const std::vector<Case> cases = {
      {"a line end after the '#'", {"LOGI:SP:050:D7#\r\n"}, "", "FB:SP:1"},
      {"two frames in one hand-over", {"LOGI:SP:050:D7#LOGI:MD:MAN:0C#"}, "", "FB:SP:1 FB:MD:1"},
      {"bytes before the header", {"xxLOGI:SP:050:D7#"}, "", "FB:SP:1"},
      {"one frame in two hand-overs", {"LOGI:SP:0", "50:D7#"}, "", "FB:SP:1"},
      {"a '#' inside the payload", {hash_inside}, "FB:GS:0", ""},
  };
  for (const auto& c : cases) {
    LogiBench firmware(logi::Dialect::firmware);
    LogiBench guide(logi::Dialect::guide);
    std::vector<std::string_view> pieces(c.pieces.begin(), c.pieces.end());
    std::string got_firmware;
    std::string got_guide;
    for (const auto p : pieces) {
      got_firmware += firmware.feedback({p});
      got_guide += guide.feedback({p});
    }
    EXPECT_EQ(got_firmware, c.firmware) << c.what;
    EXPECT_EQ(got_guide, c.guide) << c.what;
  }
}

TEST(LogiProfiles, BothProfilesTakeTheGuidesFramesAndRefuseShortOnes) {
  for (const auto d : {logi::Dialect::firmware, logi::Dialect::guide}) {
    LogiBench b(d);
    EXPECT_EQ(b.feedback({"LOGI:MD:MAN:0C#"}), "FB:MD:1") << logi::to_string(d);
    EXPECT_EQ(b.feedback({"LOGI:SP:030:D5#"}), "FB:SP:1") << logi::to_string(d);
    EXPECT_EQ(b.feedback({"LOGI:MV:FWD:23#"}), "FB:MV:1") << logi::to_string(d);
    // The checksum field is after the last ':' in both: FB:SP:1 sent back.
    EXPECT_EQ(b.feedback({"LOGI:FB:SP:1:35#"}), "") << logi::to_string(d);
    EXPECT_EQ(b.car.firmware().stats().bad_frames, 1u) << logi::to_string(d);
  }
  // Nine bytes: under the firmware's 10.
  LogiBench b(logi::Dialect::firmware);
  EXPECT_EQ(b.feedback({"LOGI::65#"}), "");
  EXPECT_EQ(b.car.firmware().stats().bad_frames, 1u);
}

// ------------------------------------------------------------------ Leka

using Car = test::VirtualCar<LekaFirmware>;

const Bytes kGeneratorDemo = hex("2A 2B 2C 2D 05 16 12 64 96 C8 77");

ServerOptions raw_link() {
  ServerOptions options;
  options.protocol = link::protocol_adapter("raw");
  return options;
}

Car make_car(Dialect dialect) {
  LekaConfig config;
  config.dialect = dialect;
  return Car(
      sim::leka_robot(),
      [config](sim::World& w, sim::Vehicle& v) {
        return std::make_unique<LekaFirmware>(w, v, config);
      },
      raw_link());
}

// Writes `bytes` and runs the main loop's next pass (10 ms grid).
void send_and_pass(Car& car, test::ClientEnd& client, const Bytes& bytes) {
  client.write(bytes);
  const auto period = car.firmware().config().loop_period;
  car.run_until(link::Time((car.now() / period + 1) * period));
}

TEST(LekaProfiles, ComspecsV3RunsTheGeneratorsDemoFrame) {
  auto car = make_car(Dialect::comspecs_v3);
  auto client = car.connect();
  send_and_pass(car, *client, kGeneratorDemo);
  const LekaState& state = car.firmware().state();
  EXPECT_EQ(state.belt[0x12], (Rgb{100, 150, 200}));
  EXPECT_EQ(state.belt[0x11], Rgb{});
  EXPECT_EQ(state.counters.commands_run, 1u);
  EXPECT_EQ(car.firmware().stats().bad_frames, 0u);
}

TEST(LekaProfiles, ReadmeRefusesTheDemoFrameOnItsChecksum) {
  auto car = make_car(Dialect::readme);
  auto client = car.connect();
  send_and_pass(car, *client, kGeneratorDemo);
  const LekaState& state = car.firmware().state();
  EXPECT_EQ(state.belt[0x12], Rgb{});
  EXPECT_EQ(state.counters.commands_run, 0u);
  EXPECT_EQ(state.counters.bad_checksum, 1u);
}

TEST(LekaProfiles, ComspecsV3RefusesTheReadmesWorkedFrame) {
  // The README's belt single LED 0 red: 0x15 is belt range in the YAML's
  // table and the checksum is not the 8-bit one, so nothing lights.
  auto car = make_car(Dialect::comspecs_v3);
  auto client = car.connect();
  send_and_pass(car, *client, hex("2A 2B 2C 2D 05 15 00 FF 00 00 41"));
  EXPECT_EQ(car.firmware().state().belt[0], Rgb{});
  EXPECT_EQ(car.firmware().state().counters.bad_checksum, 1u);
}

TEST(LekaProfiles, EachProfileAnswersInfoFramedItsOwnWay) {
  for (const Dialect d : {Dialect::readme, Dialect::comspecs_v3}) {
    auto car = make_car(d);
    auto client = car.connect();
    // readme: 2A 2B 2C 2D 01 70 70; comspecs-v3: ... 01 70 F0.
    send_and_pass(car, *client, leka::encode(leka::CommandGroup{{leka::Info{}}}, {}, d));
    EXPECT_EQ(client->take_text(), "LEKA name=leka firmware=1.0.0 buffer=128 state=ok\r\n")
        << leka::to_string(d);
    const Bytes other = leka::encode(leka::CommandGroup{{leka::Info{}}}, {},
                                     d == Dialect::readme ? Dialect::comspecs_v3 : Dialect::readme);
    send_and_pass(car, *client, other);
    EXPECT_EQ(client->take_text(), "") << leka::to_string(d);
  }
}

TEST(LekaProfiles, ComspecsV3EarRangeLightsBothEars) {
  // YAML id 0x12, ears 0..1 red; the 8-bit checksum by hand: 06, ror+12 =
  // 15, ror+00 = 8A, ror+01 = 46, ror+FF = 22, ror+00 = 11, ror+00 = 88.
  const Bytes frame = hex("2A 2B 2C 2D 06 12 00 01 FF 00 00 88");
  EXPECT_EQ(leka::encode(leka::CommandGroup{{leka::EarRange{0, 1, Rgb{255, 0, 0}}}}, {},
                         Dialect::comspecs_v3),
            frame);
  auto car = make_car(Dialect::comspecs_v3);
  auto client = car.connect();
  send_and_pass(car, *client, frame);
  EXPECT_EQ(car.firmware().state().ears[0], (Rgb{255, 0, 0}));
  EXPECT_EQ(car.firmware().state().ears[1], (Rgb{255, 0, 0}));
  EXPECT_EQ(car.firmware().state().counters.commands_run, 1u);
}

TEST(LekaProfiles, BeltLedTwentyIsOutOfRangeInBothProfiles) {
  for (const Dialect d : {Dialect::readme, Dialect::comspecs_v3}) {
    auto car = make_car(d);
    auto client = car.connect();
    const char* group = d == Dialect::readme ? "15 14 FF 00 00" : "16 14 FF 00 00";
    send_and_pass(car, *client, leka::frame_group(hex(group), d));
    EXPECT_EQ(car.firmware().state().counters.commands_run, 0u) << leka::to_string(d);
    EXPECT_EQ(car.firmware().state().belt.size(), 20u);
    send_and_pass(
        car, *client,
        leka::frame_group(hex(d == Dialect::readme ? "15 13 FF 00 00" : "16 13 FF 00 00"), d));
    EXPECT_EQ(car.firmware().state().belt[19], (Rgb{255, 0, 0})) << leka::to_string(d);
  }
}

TEST(LekaProfiles, TheLinkInFrontFramesByTheRobotsProfile) {
  for (const Dialect d : {Dialect::readme, Dialect::comspecs_v3}) {
    sim::World world(sim::WorldDef{});
    auto& vehicle = world.add_vehicle(sim::leka_robot());
    LekaConfig config;
    config.dialect = d;
    const LekaFirmware firmware(world, vehicle, config);
    EXPECT_EQ(firmware.adapter()->profile(), leka::to_string(d));
    std::vector<link::WireFrame> frames;
    firmware.adapter()->splitter()->feed(kGeneratorDemo, frames);
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0].valid, d == Dialect::comspecs_v3) << frames[0].text;
  }
}

}  // namespace
}  // namespace hil::mocks
