// The mock Leka Alpha firmware's input handling under the virtual-time
// driver: bad frames and garbage, the 128-byte serial buffer, and properties
// over random command groups and noisy streams. The commands themselves:
// leka_test.cpp.

#include "mocks/leka.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "protocol/common/overloaded.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/leka_test_support.hpp"
#include "tests/protocol/leka/leka_generators.hpp"

namespace hil::mocks::test {
namespace {

// ------------------------------------------------------------ bad input

TEST_F(LekaTest, BadChecksumIsDroppedSilentlyAndTheNextFrameStillRuns) {
  client->write(concat({hex("2A 2B 2C 2D 05 15 00 FF 00 00 42"), kSeedInfo}));
  car.run_until(at_ms(10));
  EXPECT_EQ(state().belt[0], kOff);
  EXPECT_EQ(state().counters.bad_checksum, 1u);
  EXPECT_EQ(car.firmware().stats().bad_frames, 1u);
  EXPECT_EQ(client->take_text(), kInfoLine);  // only the info, nothing for the bad frame
}

TEST_F(LekaTest, GarbageIsDroppedAndCounted) {
  client->write(protocol::to_bytes("hello robot"));
  car.run_until(at_ms(10));
  EXPECT_EQ(state().counters.garbage, 1u);
  EXPECT_EQ(car.firmware().stats().bad_frames, 1u);
  EXPECT_EQ(car.firmware().stats().frames_in, 0u);
  EXPECT_EQ(state().serial_buffered, 0u);
  EXPECT_EQ(client->text(), "");
  // Garbage right before a frame does not hide it.
  send_and_pass(concat({protocol::to_bytes("xx"), kSeedBeltRed}));
  EXPECT_EQ(state().belt[0], kRed);
  EXPECT_EQ(state().counters.garbage, 2u);
}

TEST_F(LekaTest, ShortGarbageWaitsForMoreBytesLikeTheRobotsParser) {
  // Under a minimal frame's 7 bytes the parser waits; then the garbage goes
  // with the frame that follows it.
  send_and_pass(protocol::to_bytes("junk"));
  EXPECT_EQ(state().serial_buffered, 4u);
  EXPECT_EQ(state().counters.garbage, 0u);
  send_and_pass(kSeedInfo);
  EXPECT_EQ(state().counters.garbage, 1u);
  EXPECT_EQ(client->take_text(), kInfoLine);
}

TEST_F(LekaTest, AStartSequenceSplitAcrossPassesSurvivesThePurge) {
  send_and_pass(concat({protocol::to_bytes("junkjunk"), hex("2A 2B")}));
  EXPECT_EQ(state().counters.garbage, 1u);
  EXPECT_EQ(state().serial_buffered, 2u);
  send_and_pass(hex("2C 2D 01 70 70"));
  EXPECT_EQ(client->take_text(), kInfoLine);
  EXPECT_EQ(state().counters.garbage, 1u);
}

TEST_F(LekaTest, OversizedLengthZeroLengthAndUnknownIdsAreDropped) {
  // Length 0x7B: a 123-byte group cannot fit the 128-byte buffer.
  send_and_pass(hex("2A 2B 2C 2D 7B"));
  EXPECT_EQ(state().counters.oversized, 1u);
  send_and_pass(hex("2A 2B 2C 2D 00"));
  EXPECT_EQ(state().counters.bad_format, 1u);
  send_and_pass(leka::frame_group(hex("99 01 02")));
  EXPECT_EQ(state().counters.unknown_code, 1u);
  // A known command cut short by the group's end.
  send_and_pass(leka::frame_group(hex("11 FF 00")));
  EXPECT_EQ(state().counters.bad_format, 2u);
  EXPECT_EQ(state().ears[0], kOff);
  EXPECT_EQ(car.firmware().stats().bad_frames, 4u);
  EXPECT_EQ(state().counters.commands_run, 0u);
  EXPECT_EQ(client->text(), "");
}

TEST_F(LekaTest, OutOfRangeValuesDropTheWholeFrame) {
  // Ear id 2 after a valid command: nothing of the group runs.
  send_and_pass(leka::frame_group(hex("13 FF 00 00 12 02 00 00 FF")));
  EXPECT_EQ(state().counters.bad_value, 1u);
  EXPECT_EQ(state().belt[0], kOff);
  send_and_pass(leka::frame_group(hex("21 02 80")));           // spin 2
  send_and_pass(leka::frame_group(hex("15 14 FF 00 00")));     // belt id 20
  send_and_pass(leka::frame_group(hex("50 56")));              // motivator id 0x56
  send_and_pass(leka::frame_group(hex("14 05 03 FF 00 00")));  // first > last
  EXPECT_EQ(state().counters.bad_value, 5u);
  EXPECT_EQ(chassis().left_pwm(), 0);
  EXPECT_FALSE(state().behaviour.has_value());
  EXPECT_EQ(state().counters.commands_run, 0u);
}

TEST(LekaFirmwareLenient, OutOfRangeValuesRunClampedWhenAccepted) {
  LekaConfig config;
  config.accept_out_of_range = true;
  auto car = make_car(config);
  auto client = car.connect();
  // Ear id 2 (no such ear), belt 18..25 (cut at 19), spin 2 (backward).
  client->write(leka::frame_group(hex("12 02 FF 00 00 14 12 19 00 FF 00 21 02 80")));
  car.run_until(at_ms(10));
  const auto& s = car.firmware().state();
  EXPECT_EQ(s.counters.tolerated, 1u);
  EXPECT_EQ(s.counters.bad_value, 0u);
  EXPECT_EQ(s.ears[0], kOff);
  EXPECT_EQ(s.belt[17], kOff);
  EXPECT_EQ(s.belt[18], kGreen);
  EXPECT_EQ(s.belt[19], kGreen);
  EXPECT_EQ(car.vehicle().differential()->left_pwm(), -128);
}

TEST(LekaFirmwareLenient, AWiderBeltLimitGivesMoreLeds) {
  LekaConfig config;
  config.max_belt_led_id = 0x19;  // the seed table's literal range
  auto car = make_car(config);
  auto client = car.connect();
  client->write(leka::encode(leka::CommandGroup{{leka::BeltSingle{25, kRed}}}, {0x19}));
  car.run_until(at_ms(10));
  ASSERT_EQ(car.firmware().state().belt.size(), 26u);
  EXPECT_EQ(car.firmware().state().belt[25], kRed);
}

// ------------------------------------------------------------ serial buffer

TEST_F(LekaTest, BytesBeyondTheFullSerialBufferAreLost) {
  // 106 + 4 * 7 = 134 bytes at once: 128 fit, the last 6 bytes are lost,
  // so the fourth info keeps only its first byte.
  client->write(concat({kSeedBelt20, kSeedInfo, kSeedInfo, kSeedInfo, kSeedInfo}));
  car.run_until(at_ms(9));
  EXPECT_EQ(state().counters.bytes_lost, 6u);
  EXPECT_EQ(state().serial_buffered, 128u);
  car.run_until(at_ms(10));
  EXPECT_EQ(state().belt[19], kWhite);
  EXPECT_EQ(client->take_text(), kInfoLine + kInfoLine + kInfoLine);
  EXPECT_EQ(state().serial_buffered, 1u);  // 2A: could start a frame
  // The next frame is found after that stray byte.
  send_and_pass(kSeedInfo);
  EXPECT_EQ(client->take_text(), kInfoLine);
  EXPECT_EQ(state().counters.garbage, 1u);
  EXPECT_EQ(car.firmware().stats().bytes_in, 134u + 7u);
}

TEST_F(LekaTest, EachPassEmptiesTheBufferSoPacedFramesAreNotLost) {
  client->write(kSeedBelt20);  // 1 ms
  car.run_until(at_ms(5));
  client->write(kSeedBelt20);  // 5 ms: the buffer still holds the first
  car.run_until(at_ms(10));
  EXPECT_EQ(state().counters.bytes_lost, 84u);
  EXPECT_EQ(state().serial_buffered, 22u);  // the second frame's head waits for the rest

  // Paced one frame per pass: nothing is lost.
  auto paced_car = make_car();
  auto paced = paced_car.connect();
  paced->write(kSeedBelt20);
  paced_car.run_until(at_ms(11));
  paced->write(kSeedBelt20);
  paced_car.run_until(at_ms(20));
  EXPECT_EQ(paced_car.firmware().state().counters.bytes_lost, 0u);
  EXPECT_EQ(paced_car.firmware().state().counters.commands_run, 40u);
}

TEST_F(LekaTest, AFrameCutByOverflowHoldsLaterFramesUntilItsLengthIsIn) {
  client->write(concat({kSeedBelt20, kSeedBelt20}));  // 22 bytes of the second frame fit
  car.run_until(at_ms(10));
  EXPECT_EQ(state().counters.bytes_lost, 84u);
  // Twelve infos (84 bytes) complete the cut frame's announced 106 bytes;
  // its checksum fails and the parser finds the infos inside it.
  for (int i = 0; i < 11; ++i)
    send_and_pass(kSeedInfo);
  EXPECT_EQ(client->text(), "");
  send_and_pass(kSeedInfo);
  EXPECT_EQ(state().counters.bad_checksum, 1u);
  std::string twelve;
  for (int i = 0; i < 12; ++i)
    twelve += kInfoLine;
  EXPECT_EQ(client->take_text(), twelve);
}

// ------------------------------------------------------------ properties

// What the LEDs and motors should show after a group of LED, motor and stop
// commands, worked out command by command from the profile's table.
struct Expected {
  std::array<Rgb, 2> ears{};
  std::array<Rgb, 20> belt{};
  LekaMotor left;
  LekaMotor right;

  void apply(const leka::Command& command) {
    std::visit(protocol::Overloaded{
                   [](const leka::Info&) {},
                   [](const leka::Motivator&) {},
                   [](const leka::Guidance&) {},
                   [&](const leka::StopLed&) { leds_off(); },
                   [&](const leka::StopMotor&) { left = right = {}; },
                   [&](const leka::StopRobot&) {
                     leds_off();
                     left = right = {};
                   },
                   [&](const leka::EarAll& c) {
                     ears = {c.color, c.color};
                   },
                   [&](const leka::EarRange& c) {
                     for (std::size_t i = c.first; i <= c.last; ++i)
                       ears.at(i) = c.color;
                   },
                   [&](const leka::EarSingle& c) { ears.at(c.led) = c.color; },
                   [&](const leka::BeltAll& c) { belt.fill(c.color); },
                   [&](const leka::BeltRange& c) {
                     for (std::size_t i = c.first; i <= c.last; ++i)
                       belt.at(i) = c.color;
                   },
                   [&](const leka::BeltSingle& c) { belt.at(c.led) = c.color; },
                   [&](const leka::MotorAll& c) {
                     left = right = {c.direction, c.speed};
                   },
                   [&](const leka::MotorDuo& c) {
                     left = {c.left_spin, c.left_speed};
                     right = {c.right_spin, c.right_speed};
                   },
                   [&](const leka::MotorLeft& c) {
                     left = {c.spin, c.speed};
                   },
                   [&](const leka::MotorRight& c) {
                     right = {c.spin, c.speed};
                   },
               },
               command);
  }
  void leds_off() {
    ears.fill(kOff);
    belt.fill(kOff);
  }
};

bool plays(const leka::Command& c) {
  return std::holds_alternative<leka::Motivator>(c) || std::holds_alternative<leka::Guidance>(c);
}

RC_GTEST_PROP(LekaFirmwareProperties, AGroupLeavesTheLedsAndMotorsItsCommandsSay,
              (leka::CommandGroup group)) {
  // Behaviours draw their own patterns; they have their own tests.
  std::erase_if(group.commands, plays);
  RC_PRE(!group.commands.empty());
  Expected expected;
  for (const auto& c : group.commands)
    expected.apply(c);

  auto car = make_car();
  auto client = car.connect();
  client->write(leka::encode(group));
  car.run_until(at_ms(10));
  const auto& s = car.firmware().state();
  RC_ASSERT(s.counters.commands_run == group.commands.size());
  RC_ASSERT(s.ears == expected.ears);
  RC_ASSERT(std::equal(s.belt.begin(), s.belt.end(), expected.belt.begin(), expected.belt.end()));
  RC_ASSERT(s.left == expected.left);
  RC_ASSERT(s.right == expected.right);
  RC_ASSERT(car.vehicle().differential()->left_pwm() == car.firmware().pwm_of(expected.left));
  RC_ASSERT(car.vehicle().differential()->right_pwm() == car.firmware().pwm_of(expected.right));
}

RC_GTEST_PROP(LekaFirmwareProperties, AnyInputOnlyEverGetsWholeInfoLinesBack, ()) {
  // Frames mixed with random bytes, written in random pieces at random times.
  const auto groups = *rc::gen::resize(8, rc::gen::arbitrary<std::vector<leka::CommandGroup>>());
  Bytes stream;
  for (const auto& g : groups) {
    const auto noise = *rc::gen::resize(20, rc::gen::arbitrary<Bytes>());
    stream.insert(stream.end(), noise.begin(), noise.end());
    const auto f = leka::encode(g);
    stream.insert(stream.end(), f.begin(), f.end());
  }
  auto car = make_car();
  auto client = car.connect();
  std::size_t at = 0;
  while (at < stream.size()) {
    const auto n = *rc::gen::inRange<std::size_t>(1, stream.size() - at + 1);
    client->write(Bytes(stream.begin() + static_cast<std::ptrdiff_t>(at),
                        stream.begin() + static_cast<std::ptrdiff_t>(at + n)));
    at += n;
    car.run_for(milliseconds(*rc::gen::inRange(1, 30)));
  }
  car.run_for(milliseconds(20));
  const auto& s = car.firmware().state();
  std::string lines;
  for (std::uint64_t i = 0; i < s.counters.info_answers; ++i)
    lines += kInfoLine;
  RC_ASSERT(client->text() == lines);
  RC_ASSERT(car.firmware().stats().bytes_in == stream.size());
  RC_ASSERT(s.serial_buffered <= 128u);
}

}  // namespace
}  // namespace hil::mocks::test
