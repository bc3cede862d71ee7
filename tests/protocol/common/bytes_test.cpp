#include <gtest/gtest.h>

#include "protocol/common/bytes.hpp"
#include "protocol/common/text.hpp"

namespace hil::protocol {
namespace {

TEST(Bytes, HexIsSpacedUppercase) {
  EXPECT_EQ(to_hex(Bytes{0x2A, 0x0b, 0xff}), "2A 0B FF");
  EXPECT_EQ(to_hex(Bytes{}), "");
}

TEST(Bytes, ParsesHexInTheFormsPeopleWrite) {
  EXPECT_EQ(parse_hex("2A 2B 2C 2D"), (Bytes{0x2A, 0x2B, 0x2C, 0x2D}));
  EXPECT_EQ(parse_hex("2a2b"), (Bytes{0x2A, 0x2B}));
  EXPECT_EQ(parse_hex("0x2A,0x2B"), (Bytes{0x2A, 0x2B}));
  EXPECT_EQ(parse_hex(""), Bytes{});
}

TEST(Bytes, RejectsBadHex) {
  EXPECT_FALSE(parse_hex("2A 2"));
  EXPECT_FALSE(parse_hex("2 A"));
  EXPECT_FALSE(parse_hex("GG"));
  EXPECT_FALSE(parse_hex("2A-2B"));
}

TEST(Bytes, EscapeShowsNonPrintableBytes) {
  EXPECT_EQ(escape(Bytes{'L', 0x00, '\n', '\\', 0xFF}), "L\\x00\\x0A\\\\\\xFF");
}

TEST(Text, DecimalIsStrict) {
  EXPECT_EQ(parse_decimal("050", false), 50);
  EXPECT_EQ(parse_decimal("-90", true), -90);
  EXPECT_EQ(parse_decimal("+5", true, true), 5);
  EXPECT_FALSE(parse_decimal("+5", true));
  EXPECT_FALSE(parse_decimal("-90", false));
  EXPECT_FALSE(parse_decimal("", true));
  EXPECT_FALSE(parse_decimal("-", true));
  EXPECT_FALSE(parse_decimal("1 2", false));
  EXPECT_FALSE(parse_decimal("1234567890", false));  // more than 9 digits
}

TEST(Text, HexByteReportsLowercase) {
  bool lower = true;
  EXPECT_EQ(parse_hex_byte("D7", &lower), 0xD7);
  EXPECT_FALSE(lower);
  EXPECT_EQ(parse_hex_byte("d7", &lower), 0xD7);
  EXPECT_TRUE(lower);
  EXPECT_FALSE(parse_hex_byte("D", &lower));
  EXPECT_FALSE(parse_hex_byte("DG", &lower));
}

TEST(Text, SplitKeepsEmptyPieces) {
  EXPECT_EQ(split("a,,b", ','), (std::vector<std::string_view>{"a", "", "b"}));
  EXPECT_EQ(split("", ','), (std::vector<std::string_view>{""}));
}

}  // namespace
}  // namespace hil::protocol
