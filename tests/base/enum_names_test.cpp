// Enum name tables: a value's name, the value of a name, and the list an
// error message shows.
#include "base/enum_names.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>

namespace hil::base {
namespace {

enum class Colour : std::uint8_t { red, green, blue, unnamed };

constexpr auto kColourNames =
    enum_names<Colour>({Colour::blue, "blue"}, {Colour::red, "red"}, {Colour::green, "green"});

// The whole table works at compile time.
static_assert(kColourNames.size() == 3);
static_assert(kColourNames.name(Colour::green) == "green");
static_assert(kColourNames.parse("red") == Colour::red);
static_assert(!kColourNames.parse("Red"));

TEST(EnumNames, NamesEachValueAsPairedNotByIndex) {
  EXPECT_EQ(kColourNames.name(Colour::red), "red");
  EXPECT_EQ(kColourNames.name(Colour::green), "green");
  EXPECT_EQ(kColourNames.name(Colour::blue), "blue");
}

TEST(EnumNames, AValueLeftOutGetsTheFallback) {
  EXPECT_EQ(kColourNames.name(Colour::unnamed), "?");
  EXPECT_EQ(kColourNames.name(Colour::unnamed, "none"), "none");
  EXPECT_EQ(kColourNames.name(static_cast<Colour>(200), ""), "");
  EXPECT_FALSE(kColourNames.find(Colour::unnamed));
  EXPECT_EQ(kColourNames.find(Colour::blue), "blue");
}

TEST(EnumNames, ParsesExactlyTheNames) {
  EXPECT_EQ(kColourNames.parse("blue"), Colour::blue);
  EXPECT_EQ(kColourNames.parse("green"), Colour::green);
  for (const char* word : {"", "?", "BLUE", " red", "gree", "greens", "unnamed"})
    EXPECT_FALSE(kColourNames.parse(word)) << word;
}

TEST(EnumNames, PrintingAndParsingAgree) {
  for (const auto& entry : kColourNames) {
    EXPECT_EQ(kColourNames.parse(kColourNames.name(entry.value)), entry.value);
  }
}

TEST(EnumNames, ListsTheNamesInTableOrder) {
  EXPECT_EQ(kColourNames.list(), "blue, red, green");
  EXPECT_EQ(kColourNames.list(" or "), "blue, red or green");
  EXPECT_EQ(kColourNames.names(), (std::vector<std::string>{"blue", "red", "green"}));
}

TEST(EnumNames, ListsOneOrTwoNames) {
  constexpr auto two = enum_names<Colour>({Colour::red, "red"}, {Colour::blue, "blue"});
  EXPECT_EQ(two.list(" or "), "red or blue");
  constexpr auto one = enum_names<Colour>({Colour::red, "red"});
  EXPECT_EQ(one.list(" or "), "red");
}

TEST(EnumNames, NamesIntegerCodesToo) {
  constexpr auto codes = enum_names<int>({2, "INT"}, {15, "TERM"});
  EXPECT_EQ(codes.name(15), "TERM");
  EXPECT_FALSE(codes.find(9));
  EXPECT_EQ(codes.parse("INT"), 2);
}

TEST(EnumNames, TakesUpToTheMostEntries) {
  constexpr auto many = enum_names<int>(
      {0, "a"}, {1, "b"}, {2, "c"}, {3, "d"}, {4, "e"}, {5, "f"}, {6, "g"}, {7, "h"}, {8, "i"},
      {9, "j"}, {10, "k"}, {11, "l"}, {12, "m"}, {13, "n"}, {14, "o"}, {15, "p"}, {16, "q"},
      {17, "r"}, {18, "s"}, {19, "t"}, {20, "u"}, {21, "v"}, {22, "w"}, {23, "x"}, {24, "y"},
      {25, "z"}, {26, "A"}, {27, "B"}, {28, "C"}, {29, "D"}, {30, "E"}, {31, "F"});
  static_assert(many.size() == kMaxEnumNames);
  EXPECT_EQ(many.name(31), "F");
  EXPECT_EQ(many.parse("a"), 0);
}

TEST(EnumNames, RefusesARepeatedValueOrName) {
  using Entries = std::array<EnumName<Colour>, 2>;
  EXPECT_THROW((EnumNames<Colour, 2>(Entries{{{Colour::red, "red"}, {Colour::red, "rouge"}}})),
               std::logic_error);
  EXPECT_THROW((EnumNames<Colour, 2>(Entries{{{Colour::red, "red"}, {Colour::blue, "red"}}})),
               std::logic_error);
}

}  // namespace
}  // namespace hil::base
