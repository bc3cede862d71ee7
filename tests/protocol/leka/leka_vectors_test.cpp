// The three complete frames of the Leka specification are test vectors:
// encode must produce them byte for byte, and decode must give the commands
// back. Also the wire form of every command of the table.

#include <gtest/gtest.h>

#include "protocol/leka/codec.hpp"
#include "tests/support/hex.hpp"

namespace hil::protocol::leka {
namespace {

using test::hex;

CommandGroup belt_of_twenty() {
  // The seed's 20-LED example: LED i gets the i-th colour of this list.
  const Rgb colors[20] = {{0x33, 0, 0}, {0x66, 0, 0}, {0x99, 0, 0}, {0xCC, 0, 0},
                          {0xFF, 0, 0}, {0, 0, 0},    {0, 0x33, 0}, {0, 0x66, 0},
                          {0, 0x99, 0}, {0, 0xCC, 0}, {0, 0xFF, 0}, {0, 0, 0},
                          {0, 0, 0x33}, {0, 0, 0x66}, {0, 0, 0x99}, {0, 0, 0xCC},
                          {0xFF, 0, 0}, {0, 0xFF, 0}, {0, 0, 0xFF}, {0xFF, 0xFF, 0xFF}};
  CommandGroup g;
  for (std::uint8_t i = 0; i < 20; ++i)
    g.commands.push_back(BeltSingle{i, colors[i]});
  return g;
}

const std::string_view kBeltFrame =
    "2A 2B 2C 2D 64 15 00 33 00 00 15 01 66 00 00 15 02 99 00 00 15 03 CC 00 00 15 04 FF 00 00 "
    "15 05 00 00 00 15 06 00 33 00 15 07 00 66 00 15 08 00 99 00 15 09 00 CC 00 15 0A 00 FF 00 "
    "15 0B 00 00 00 15 0C 00 00 33 15 0D 00 00 66 15 0E 00 00 99 15 0F 00 00 CC 15 10 FF 00 00 "
    "15 11 00 FF 00 15 12 00 00 FF 15 13 FF FF FF A8";

struct Vector {
  std::string_view frame;
  CommandGroup group;
};

std::vector<Vector> seed_vectors() {
  return {
      {"2A 2B 2C 2D 05 15 00 FF 00 00 41", CommandGroup{{BeltSingle{0, Rgb{255, 0, 0}}}}},
      {"2A 2B 2C 2D 01 70 70", CommandGroup{{Info{}}}},
      {kBeltFrame, belt_of_twenty()},
  };
}

TEST(LekaVectors, EncodeReproducesEverySeedFrame) {
  for (const auto& v : seed_vectors()) {
    EXPECT_EQ(to_hex(encode(v.group)), to_hex(hex(v.frame))) << describe(v.group);
  }
}

TEST(LekaVectors, DecodeGivesBackEverySeedGroup) {
  for (const auto& v : seed_vectors()) {
    const Bytes raw = hex(v.frame);
    const auto item = decode_frame(raw);
    const auto* frame = std::get_if<Frame<Message>>(&item);
    ASSERT_NE(frame, nullptr) << v.frame << ": " << std::get<DecodeError>(item).detail;
    EXPECT_EQ(frame->message, v.group) << v.frame;
    EXPECT_EQ(frame->raw, raw);
    EXPECT_FALSE(frame->tolerated);
  }
}

TEST(LekaVectors, SeedBeltFrameIs106BytesWithTwentyCommands) {
  const Bytes raw = hex(kBeltFrame);
  EXPECT_EQ(raw.size(), 106u);
  EXPECT_EQ(raw[4], 100u);
  EXPECT_EQ(belt_of_twenty().commands.size(), 20u);
}

TEST(LekaVectors, ChecksumIsLowByteOfBsdSumOverTheGroupOnly) {
  EXPECT_EQ(bsd_checksum16(hex("15 00 FF 00 00")), 0x1041);
  EXPECT_EQ(checksum(hex("15 00 FF 00 00")), 0x41);
  EXPECT_EQ(checksum(hex("70")), 0x70);
  const Bytes belt = hex(kBeltFrame);
  EXPECT_EQ(bsd_checksum16(ByteView(belt).subspan(5, 100)), 0x35A8);
  // The seed's prose also names the length byte as an input. For the two
  // short frames that makes no difference (after 5 or 1 rotations its bits
  // sit in the high byte, which is dropped); only the 106-byte frame tells
  // the two readings apart, and it matches the group-only one.
  EXPECT_EQ(checksum(hex("05 15 00 FF 00 00")), 0x41);
  EXPECT_EQ(checksum(hex("01 70")), 0x70);
  EXPECT_EQ(checksum(ByteView(belt).subspan(4, 101)), 0xAE);
  EXPECT_NE(checksum(ByteView(belt).subspan(4, 101)), belt.back());
}

TEST(LekaVectors, EveryCommandHasItsTableIdAndSize) {
  struct Case {
    Command command;
    std::string_view bytes;
  };
  const Case cases[] = {
      {Info{}, "70"},
      {StopLed{}, "FD"},
      {StopMotor{}, "FE"},
      {StopRobot{}, "FF"},
      {EarAll{Rgb{1, 2, 3}}, "11 01 02 03"},
      {EarSingle{1, Rgb{4, 5, 6}}, "12 01 04 05 06"},
      {BeltAll{Rgb{7, 8, 9}}, "13 07 08 09"},
      {BeltRange{2, 9, Rgb{10, 11, 12}}, "14 02 09 0A 0B 0C"},
      {BeltSingle{19, Rgb{13, 14, 15}}, "15 13 0D 0E 0F"},
      {MotorAll{kSpinBackward, 200}, "21 01 C8"},
      {MotorDuo{kSpinForward, 100, kSpinBackward, 150}, "22 00 64 01 96"},
      {MotorLeft{kSpinForward, 255}, "23 00 FF"},
      {MotorRight{kSpinBackward, 1}, "24 01 01"},
      {Motivator{0x53}, "50 53"},
      {Guidance{0x4F}, "40 4F"},
  };
  // Every command of the README's table (led.ear.range is not one).
  EXPECT_EQ(std::size(cases), kCommandSpecs.size() - 1);
  for (const auto& c : cases) {
    const Bytes group = group_bytes(CommandGroup{{c.command}});
    EXPECT_EQ(to_hex(group), to_hex(hex(c.bytes))) << describe(c.command);
    EXPECT_EQ(group.size(), 1 + spec_of(c.command).data_bytes);
    const auto parsed = parse_group(group);
    ASSERT_TRUE(std::holds_alternative<CommandGroup>(parsed)) << describe(c.command);
    EXPECT_EQ(std::get<CommandGroup>(parsed).commands, std::vector<Command>{c.command});
  }
}

TEST(LekaVectors, SeveralCommandsShareOneFrame) {
  const CommandGroup g{{EarAll{Rgb{255, 0, 0}}, MotorAll{kSpinBackward, 200}}};
  const Bytes frame = encode(g);
  EXPECT_EQ(to_hex(frame), "2A 2B 2C 2D 07 11 FF 00 00 21 01 C8 D8");
  EXPECT_EQ(frame.back(), checksum(hex("11 FF 00 00 21 01 C8")));
  EXPECT_EQ(describe(g), "led.ear.all rgb=(255,0,0) + motor.all backward speed=200");
}

TEST(LekaVectors, DescribeNamesCommandsAndFields) {
  EXPECT_EQ(describe(CommandGroup{{BeltSingle{0, Rgb{255, 0, 0}}}}),
            "led.belt.single led=0 rgb=(255,0,0)");
  EXPECT_EQ(describe(Command{MotorDuo{0, 10, 1, 20}}),
            "motor.duo left=forward/10 right=backward/20");
  EXPECT_EQ(describe(Command{Guidance{0x41}}), "guidance id=0x41");
  EXPECT_EQ(describe(Command{BeltRange{1, 4, Rgb{}}}), "led.belt.range leds=1..4 rgb=(0,0,0)");
}

TEST(LekaVectors, EncodeRefusesGroupsTheRobotCannotTake) {
  EXPECT_THROW(encode(CommandGroup{}), std::invalid_argument);
  EXPECT_THROW(encode(CommandGroup{{EarSingle{2, Rgb{}}}}), std::invalid_argument);
  EXPECT_THROW(encode(CommandGroup{{BeltSingle{0x14, Rgb{}}}}), std::invalid_argument);
  EXPECT_THROW(encode(CommandGroup{{BeltRange{5, 4, Rgb{}}}}), std::invalid_argument);
  EXPECT_THROW(encode(CommandGroup{{MotorAll{2, 0}}}), std::invalid_argument);
  EXPECT_THROW(encode(CommandGroup{{MotorDuo{0, 0, 7, 0}}}), std::invalid_argument);
  EXPECT_THROW(encode(CommandGroup{{Motivator{0x56}}}), std::invalid_argument);
  EXPECT_THROW(encode(CommandGroup{{Guidance{0x40}}}), std::invalid_argument);
  // Thirty four-byte commands and two one-byte ones: 122 group bytes, the bound.
  CommandGroup big;
  for (int i = 0; i < 30; ++i)
    big.commands.push_back(BeltAll{});
  big.commands.push_back(Info{});
  big.commands.push_back(StopLed{});
  EXPECT_EQ(encode(big).size(), kMaxFrameBytes);
  big.commands.push_back(Info{});  // 123: one over
  EXPECT_THROW(encode(big), std::invalid_argument);
  // The table's literal belt range 0x00..0x19 is available as a limit.
  EXPECT_NO_THROW(encode(CommandGroup{{BeltSingle{0x19, Rgb{}}}}, ValueLimits{0x19}));
}

TEST(LekaVectors, FrameGroupFramesAnyBytesThatFitTheLengthField) {
  EXPECT_EQ(to_hex(frame_group(hex("99 01"))),
            "2A 2B 2C 2D 02 99 01 " + to_hex(Bytes{checksum(hex("99 01"))}));
  EXPECT_EQ(frame_group(Bytes(255, 0x70)).size(), 261u);
  EXPECT_THROW(frame_group(Bytes(256, 0x70)), std::invalid_argument);
}

}  // namespace
}  // namespace hil::protocol::leka
