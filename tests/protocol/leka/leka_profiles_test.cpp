// The two conventions of the Leka spec as profiles. Vectors: the frame the
// third-party generator MMyster/Leka-Command-Generator documents for belt
// single LED 0x12 RGB 100 150 200 (comspecs-v3), and the README's worked
// frames (readme); the id tables of leka/LKAlphaComSpecs at 381046f.

#include <gtest/gtest.h>

#include "protocol/common/car_profile.hpp"
#include "protocol/leka/codec.hpp"
#include "tests/support/hex.hpp"

namespace hil::protocol::leka {
namespace {

using test::hex;

constexpr std::string_view kGeneratorDemo = "2A 2B 2C 2D 05 16 12 64 96 C8 77";

DecoderOptions in(Dialect dialect) {
  DecoderOptions options;
  options.dialect = dialect;
  return options;
}

TEST(LekaProfiles, TheGeneratorsDemoFrameIsBeltSingleInComspecsV3) {
  const Bytes raw = hex(kGeneratorDemo);
  const auto item = decode_frame(raw, in(Dialect::comspecs_v3));
  const auto* frame = std::get_if<Frame<Message>>(&item);
  ASSERT_NE(frame, nullptr) << std::get<DecodeError>(item).detail;
  EXPECT_EQ(frame->message, (CommandGroup{{BeltSingle{0x12, Rgb{100, 150, 200}}}}));
  EXPECT_FALSE(frame->tolerated);
  EXPECT_EQ(to_hex(encode(frame->message, {}, Dialect::comspecs_v3)), kGeneratorDemo);
}

TEST(LekaProfiles, TheReadmeProfileRefusesTheDemoFrameAndNamesTheOtherProfile) {
  const auto item = decode_frame(hex(kGeneratorDemo), in(Dialect::readme));
  const auto* error = std::get_if<DecodeError>(&item);
  ASSERT_NE(error, nullptr);
  EXPECT_EQ(error->kind, ErrorKind::bad_checksum);
  EXPECT_NE(error->detail.find("0x77"), std::string::npos) << error->detail;
  EXPECT_NE(error->detail.find("does not match 0x2F"), std::string::npos) << error->detail;
  EXPECT_NE(error->detail.find("it matches profile comspecs-v3"), std::string::npos)
      << error->detail;
}

TEST(LekaProfiles, TheReadmesWorkedFramesFailTheComspecsChecksum) {
  for (const std::string_view frame : {std::string_view("2A 2B 2C 2D 05 15 00 FF 00 00 41"),
                                       std::string_view("2A 2B 2C 2D 01 70 70")}) {
    EXPECT_TRUE(
        std::holds_alternative<Frame<Message>>(decode_frame(hex(frame), in(Dialect::readme))))
        << frame;
    const auto item = decode_frame(hex(frame), in(Dialect::comspecs_v3));
    ASSERT_TRUE(std::holds_alternative<DecodeError>(item)) << frame;
    EXPECT_EQ(std::get<DecodeError>(item).kind, ErrorKind::bad_checksum) << frame;
    EXPECT_NE(std::get<DecodeError>(item).detail.find("it matches profile readme"),
              std::string::npos)
        << std::get<DecodeError>(item).detail;
  }
}

TEST(LekaProfiles, Bsd8ChecksumRotatesWithinOneByteOverLengthAndGroup) {
  // By hand: 0 -> +05 = 05; ror 82 +16 = 98; ror 4C +12 = 5E; ror 2F +64 = 93;
  // ror C9 +96 = 5F; ror AF +C8 = 77.
  EXPECT_EQ(bsd_checksum8(hex("05 16 12 64 96 C8")), 0x77);
  EXPECT_EQ(checksum(hex("16 12 64 96 C8"), Dialect::comspecs_v3), 0x77);
  // The README's convention over the same group: the low byte of the 16-bit sum.
  EXPECT_EQ(checksum(hex("16 12 64 96 C8"), Dialect::readme), 0x2F);
  // Info: 01 then 70, with the length byte rotated into the top bit.
  EXPECT_EQ(to_hex(encode(CommandGroup{{Info{}}}, {}, Dialect::comspecs_v3)),
            "2A 2B 2C 2D 01 70 F0");
}

TEST(LekaProfiles, CommandIdsFollowEachProfilesTable) {
  struct Case {
    Command command;
    std::string_view readme;    // "" where the README has no such command
    std::string_view comspecs;  // the YAML / Swift table
  };
  const Rgb c{1, 2, 3};
  const Case cases[] = {
      {EarAll{c}, "11 01 02 03", "11 01 02 03"},
      {EarRange{0, 1, c}, "", "12 00 01 01 02 03"},
      {EarSingle{1, c}, "12 01 01 02 03", "13 01 01 02 03"},
      {BeltAll{c}, "13 01 02 03", "14 01 02 03"},
      {BeltRange{2, 9, c}, "14 02 09 01 02 03", "15 02 09 01 02 03"},
      {BeltSingle{19, c}, "15 13 01 02 03", "16 13 01 02 03"},
      {MotorAll{kSpinBackward, 200}, "21 01 C8", "21 01 C8"},
      {MotorDuo{0, 100, 1, 150}, "22 00 64 01 96", "22 00 64 01 96"},
      {MotorLeft{0, 255}, "23 00 FF", "23 00 FF"},
      {MotorRight{1, 1}, "24 01 01", "24 01 01"},
      {Guidance{0x4F}, "40 4F", "40 4F"},
      {Motivator{0x53}, "50 53", "50 53"},
      {Info{}, "70", "70"},
      {StopLed{}, "FD", "FD"},
      {StopMotor{}, "FE", "FE"},
      {StopRobot{}, "FF", "FF"},
  };
  EXPECT_EQ(std::size(cases), kCommandSpecs.size());
  for (const auto& k : cases) {
    const CommandGroup g{{k.command}};
    EXPECT_EQ(to_hex(group_bytes(g, Dialect::comspecs_v3)), k.comspecs) << describe(g);
    const auto parsed = parse_group(hex(k.comspecs), Dialect::comspecs_v3);
    ASSERT_TRUE(std::holds_alternative<CommandGroup>(parsed)) << k.comspecs;
    EXPECT_EQ(std::get<CommandGroup>(parsed), g) << k.comspecs;
    if (k.readme.empty()) {
      EXPECT_THROW(group_bytes(g, Dialect::readme), std::invalid_argument) << describe(g);
      EXPECT_THROW(encode(g, {}, Dialect::readme), std::invalid_argument) << describe(g);
    } else {
      EXPECT_EQ(to_hex(group_bytes(g, Dialect::readme)), k.readme) << describe(g);
    }
  }
}

TEST(LekaProfiles, TheSameIdMeansAnotherCommandInTheOtherProfile) {
  // 0x12 0x00 0x01 ...: ear single LED 0 in the README's table; the first
  // two data bytes of an ear range in the YAML's, which needs five.
  const auto readme = parse_group(hex("12 00 01 02 03"), Dialect::readme);
  ASSERT_TRUE(std::holds_alternative<CommandGroup>(readme));
  EXPECT_EQ(std::get<CommandGroup>(readme), (CommandGroup{{EarSingle{0, Rgb{1, 2, 3}}}}));
  const auto comspecs = parse_group(hex("12 00 01 02 03"), Dialect::comspecs_v3);
  ASSERT_TRUE(std::holds_alternative<GroupError>(comspecs));
  EXPECT_EQ(std::get<GroupError>(comspecs).kind, ErrorKind::bad_format);
  EXPECT_EQ(std::get<GroupError>(comspecs).context, "led.ear.range");
  // 0x16 is no README id; the error says what it is in comspecs-v3.
  const auto unknown = parse_group(hex("16 12 64 96 C8"), Dialect::readme);
  ASSERT_TRUE(std::holds_alternative<GroupError>(unknown));
  EXPECT_EQ(std::get<GroupError>(unknown).kind, ErrorKind::unknown_code);
  EXPECT_NE(
      std::get<GroupError>(unknown).detail.find("in profile comspecs-v3 it is led.belt.single"),
      std::string::npos)
      << std::get<GroupError>(unknown).detail;
}

TEST(LekaProfiles, BeltLedIdsAreZeroToNineteenInBoth) {
  for (const Dialect d : {Dialect::readme, Dialect::comspecs_v3}) {
    EXPECT_NO_THROW(encode(CommandGroup{{BeltSingle{19, Rgb{}}}}, {}, d));
    EXPECT_THROW(encode(CommandGroup{{BeltSingle{20, Rgb{}}}}, {}, d), std::invalid_argument);
    const Bytes twenty =
        frame_group(hex(d == Dialect::readme ? "15 14 FF 00 00" : "16 14 FF 00 00"), d);
    const auto item = decode_frame(twenty, in(d));
    ASSERT_TRUE(std::holds_alternative<DecodeError>(item)) << to_string(d);
    EXPECT_EQ(std::get<DecodeError>(item).kind, ErrorKind::bad_value) << to_string(d);
  }
}

TEST(LekaProfiles, EarRangeChecksItsIds) {
  EXPECT_FALSE(range_problem(EarRange{0, 1, Rgb{}}));
  EXPECT_TRUE(range_problem(EarRange{0, 2, Rgb{}}));
  EXPECT_TRUE(range_problem(EarRange{1, 0, Rgb{}}));
  EXPECT_EQ(describe(Command{EarRange{0, 1, Rgb{9, 8, 7}}}), "led.ear.range leds=0..1 rgb=(9,8,7)");
}

TEST(LekaProfiles, TheStreamDecoderFollowsItsProfile) {
  // The demo frame, then info, in comspecs-v3, cut into single bytes.
  Bytes stream = hex(kGeneratorDemo);
  const Bytes info = encode(CommandGroup{{Info{}}}, {}, Dialect::comspecs_v3);
  stream.insert(stream.end(), info.begin(), info.end());
  Decoder decoder(in(Dialect::comspecs_v3));
  std::vector<Item> items;
  for (const std::uint8_t b : stream)
    decoder.feed(ByteView(&b, 1), items);
  decoder.finish(items);
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(std::get<Frame<Message>>(items[0]).message,
            (CommandGroup{{BeltSingle{0x12, Rgb{100, 150, 200}}}}));
  EXPECT_EQ(std::get<Frame<Message>>(items[1]).message, (CommandGroup{{Info{}}}));
}

TEST(LekaProfiles, ProfileNamesMapToDialects) {
  EXPECT_EQ(dialect_named(""), Dialect::readme);
  EXPECT_EQ(dialect_named("readme"), Dialect::readme);
  EXPECT_EQ(dialect_named("comspecs-v3"), Dialect::comspecs_v3);
  EXPECT_EQ(to_string(Dialect::comspecs_v3), "comspecs-v3");
  try {
    (void)dialect_named("yaml");
    FAIL() << "an unknown profile was taken";
  } catch (const ProfileError& e) {
    EXPECT_STREQ(e.what(),
                 "leka has no profile 'yaml'; its profiles are readme (the default) and "
                 "comspecs-v3");
  }
}

}  // namespace
}  // namespace hil::protocol::leka
