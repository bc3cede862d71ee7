#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "protocol/common/decode.hpp"
#include "protocol/common/delimited_framer.hpp"

namespace hil::protocol {
namespace {

using Kind = DelimitedFramer::Kind;

std::vector<DelimitedFramer::Event> run(std::string_view text, std::size_t max = 32,
                                        bool finish = true) {
  DelimitedFramer framer("AB:", '#', max);
  std::vector<DelimitedFramer::Event> out;
  framer.feed(to_bytes(text), out);
  if (finish) framer.finish(out);
  return out;
}

TEST(SequenceMatcher, FindsHeaderAfterFalseStart) {
  SequenceMatcher m("LOGI:");
  std::string stream = "LOGLOGI:";
  std::size_t found_at = 0;
  for (std::size_t i = 0; i < stream.size(); ++i) {
    if (m.feed(static_cast<std::uint8_t>(stream[i]))) found_at = i;
  }
  EXPECT_EQ(found_at, 7u);
}

TEST(SequenceMatcher, HandlesSelfOverlappingPatterns) {
  SequenceMatcher m("AAB");
  int hits = 0;
  for (const char c : std::string("AAAAB"))
    hits += m.feed(static_cast<std::uint8_t>(c)) ? 1 : 0;
  EXPECT_EQ(hits, 1);
}

TEST(DelimitedFramer, SplitsGarbageAndFrames) {
  const auto events = run("xxAB:1#yAB:2#");
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events[0].kind, Kind::garbage);
  EXPECT_EQ(to_string(events[0].bytes), "xx");
  EXPECT_EQ(events[1].kind, Kind::frame);
  EXPECT_EQ(to_string(events[1].bytes), "AB:1#");
  EXPECT_EQ(events[2].kind, Kind::garbage);
  EXPECT_EQ(events[3].kind, Kind::frame);
}

TEST(DelimitedFramer, NewHeaderInterruptsAnUnterminatedFrame) {
  const auto events = run("AB:12AB:3#");
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, Kind::interrupted);
  EXPECT_EQ(to_string(events[0].bytes), "AB:12");
  EXPECT_EQ(to_string(events[1].bytes), "AB:3#");
}

TEST(DelimitedFramer, OversizedFrameIsCutAtTheBound) {
  const auto events = run("AB:0123456789AB:1#", 8);
  ASSERT_GE(events.size(), 2u);
  EXPECT_EQ(events[0].kind, Kind::oversized);
  EXPECT_EQ(events[0].bytes.size(), 9u);
  EXPECT_EQ(events.back().kind, Kind::frame);
  EXPECT_EQ(to_string(events.back().bytes), "AB:1#");
}

TEST(DelimitedFramer, BoundIncludesTheTerminator) {
  const auto fits = run("AB:12345#", 9);
  ASSERT_EQ(fits.size(), 1u);
  EXPECT_EQ(fits[0].kind, Kind::frame);
  const auto over = run("AB:123456#", 9);
  ASSERT_EQ(over.size(), 1u);
  EXPECT_EQ(over[0].kind, Kind::oversized);
  EXPECT_EQ(to_string(over[0].bytes), "AB:123456#");
}

TEST(DelimitedFramer, NeverHoldsMoreThanItsBound) {
  DelimitedFramer framer("AB:", '#', 16);
  std::vector<DelimitedFramer::Event> out;
  for (int i = 0; i < 1000; ++i) {
    framer.feed(to_bytes(i % 100 == 0 ? "AB:" : "z"), out);
    EXPECT_LE(framer.buffered(), 16u);
  }
}

TEST(DelimitedFramer, FinishReportsTruncatedFrame) {
  const auto events = run("AB:12");
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, Kind::truncated);
}

RC_GTEST_PROP(DelimitedFramer, EveryByteComesOutOnceInOrder,
              (const std::vector<std::uint8_t>& noise)) {
  // Bias the alphabet towards the header and terminator bytes.
  const auto stream = *rc::gen::container<std::vector<std::uint8_t>>(
      rc::gen::element<std::uint8_t>('A', 'B', ':', '#', 'x', 0x00));
  Bytes all = stream;
  all.insert(all.end(), noise.begin(), noise.end());
  DelimitedFramer framer("AB:", '#', 12);
  std::vector<DelimitedFramer::Event> out;
  framer.feed(all, out);
  framer.finish(out);
  Bytes joined;
  for (const auto& e : out)
    joined.insert(joined.end(), e.bytes.begin(), e.bytes.end());
  RC_ASSERT(joined == all);
}

}  // namespace
}  // namespace hil::protocol
