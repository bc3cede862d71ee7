// Durations as text: the literals of every hil file and script, and the
// seconds of reports and pictures.
#include "base/duration.hpp"

#include <gtest/gtest.h>

namespace hil {
namespace {

using namespace std::chrono_literals;
using std::chrono::nanoseconds;

TEST(Duration, LiteralsNeedAUnitAndAreExact) {
  EXPECT_EQ(parse_duration("250ms"), nanoseconds{250ms});
  EXPECT_EQ(parse_duration("2s"), nanoseconds{2s});
  EXPECT_EQ(parse_duration("1.5s"), nanoseconds{1500ms});
  EXPECT_EQ(parse_duration("0.001s"), nanoseconds{1ms});
  EXPECT_EQ(parse_duration("500us"), nanoseconds{500us});
  EXPECT_EQ(parse_duration("7ns"), nanoseconds{7});
  EXPECT_EQ(parse_duration("0s"), nanoseconds{0});
  for (const char* bad :
       {"250", "1.5", "-1s", "ms", "1.s", ".5s", "1.0.0s", "2 s", "1h", "0.5ns", ""}) {
    EXPECT_FALSE(parse_duration(bad)) << bad;
  }
}

TEST(Duration, ALiteralTooLargeForNanosecondsIsRefused) {
  EXPECT_FALSE(parse_duration("99999999999999999999s"));
  EXPECT_FALSE(parse_duration("9300000000s"));  // past 2^63 ns / 2
  EXPECT_TRUE(parse_duration("4000000000s"));
}

TEST(Duration, TheShortestLiteralReadsBackExactly) {
  EXPECT_EQ(duration_literal(2s), "2s");
  EXPECT_EQ(duration_literal(250ms), "250ms");
  EXPECT_EQ(duration_literal(1500ms), "1500ms");
  EXPECT_EQ(duration_literal(1500us), "1500us");
  EXPECT_EQ(duration_literal(nanoseconds{7}), "7ns");
  EXPECT_EQ(duration_literal(nanoseconds{0}), "0s");
  for (const nanoseconds d : {nanoseconds{123456789}, nanoseconds{5'000'000'000}, nanoseconds{1}})
    EXPECT_EQ(parse_duration(duration_literal(d)), d);
}

TEST(Duration, SecondsHaveTheDecimalsAskedFor) {
  EXPECT_EQ(seconds_text(1500ms, 3), "1.500 s");
  EXPECT_EQ(seconds_text(1500ms, 1), "1.5 s");
  EXPECT_EQ(seconds_text(nanoseconds{0}, 1), "0.0 s");
  EXPECT_EQ(seconds_text(-20ms, 1), "0.0 s");  // rounds to zero: no "-0.0"
  EXPECT_EQ(seconds_text(-200ms, 1), "-0.2 s");
  EXPECT_EQ(seconds_text(12'345'678'901ns, 3), "12.346 s");
}

}  // namespace
}  // namespace hil
