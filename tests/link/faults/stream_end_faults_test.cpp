// limit_data and slow_close: the rules that end a stream (a byte budget,
// and a close held back), in virtual time with exact bytes and times.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "link/faults/fault_injector.hpp"
#include "protocol/logi/codec.hpp"
#include "tests/link/faults/fault_test_support.hpp"

namespace hil::link {
namespace {

using namespace test;
using protocol::to_bytes;

const Bytes kTen = to_bytes("0123456789");

FaultRule named(FaultRule r, std::string name) {
  r.name = std::move(name);
  return r;
}

std::vector<Output> delivery_list(const test::Run& run) {
  return run.deliveries();
}

Bytes bytes_of(const Output& o) {
  return std::get<Delivery>(o.what).bytes;
}

// ---------------------------------------------------------------- limit_data

TEST(LimitData, TheWriteThatCrossesTheLimitIsCutAndTheLinkClosesGracefully) {
  const auto run = run_injector("raw", profile_of({rule(LimitData{25})}),
                                {{0ms, kTen}, {10ms, kTen}, {20ms, kTen}, {30ms, kTen}});
  const auto d = delivery_list(run);
  ASSERT_EQ(d.size(), 3U);
  EXPECT_EQ(d[0].at, Time{0ms});
  EXPECT_EQ(d[1].at, Time{10ms});
  EXPECT_EQ(d[2].at, Time{20ms});
  EXPECT_EQ(bytes_of(d[2]), to_bytes("01234"));
  EXPECT_EQ(run.delivered().size(), 25U);
  ASSERT_EQ(run.outputs.size(), 4U) << "nothing after the close";
  ASSERT_TRUE(std::holds_alternative<LinkBreak>(run.outputs.back().what));
  EXPECT_FALSE(std::get<LinkBreak>(run.outputs.back().what).reset);
  EXPECT_EQ(run.outputs.back().at, Time{20ms});

  const auto events = run.events_of(FaultKind::limit_data);
  ASSERT_EQ(events.size(), 1U);
  EXPECT_EQ(events[0].at, Time{20ms});
  EXPECT_EQ(events[0].frame, 3U);
  EXPECT_EQ(events[0].before, kTen);
  EXPECT_EQ(events[0].after, to_bytes("01234"));
  EXPECT_EQ(events[0].detail, "limit of 25 bytes reached: 5 of 10 bytes passed, link closed");
}

TEST(LimitData, ReachingTheLimitExactlyClosesTooAsToxiproxyDoes) {
  const auto run =
      run_injector("raw", profile_of({rule(LimitData{20})}), {{0ms, kTen}, {10ms, kTen}});
  EXPECT_EQ(run.delivered(), concat({kTen, kTen}));
  ASSERT_NE(run.link_break(), nullptr);
  EXPECT_EQ(run.outputs.back().at, Time{10ms});
  ASSERT_EQ(run.events_of(FaultKind::limit_data).size(), 1U);
  EXPECT_EQ(run.events_of(FaultKind::limit_data)[0].after, kTen);
}

TEST(LimitData, UnderTheLimitNothingHappens) {
  const auto run =
      run_injector("raw", profile_of({rule(LimitData{21})}), {{0ms, kTen}, {10ms, kTen}});
  EXPECT_EQ(run.delivered(), concat({kTen, kTen}));
  EXPECT_EQ(run.link_break(), nullptr);
  EXPECT_TRUE(run.events.empty());
}

TEST(LimitData, TheCloseFollowsTheDelayedBytes) {
  const auto run = run_injector("raw", profile_of({rule(Delay{100ms, 0ms}), rule(LimitData{15})}),
                                {{0ms, kTen}, {10ms, kTen}});
  const auto d = delivery_list(run);
  ASSERT_EQ(d.size(), 2U);
  EXPECT_EQ(d[0].at, Time{100ms});
  EXPECT_EQ(d[1].at, Time{110ms});
  EXPECT_EQ(bytes_of(d[1]), to_bytes("01234"));
  ASSERT_TRUE(std::holds_alternative<LinkBreak>(run.outputs.back().what));
  EXPECT_EQ(run.outputs.back().at, Time{110ms});
  EXPECT_EQ(run.events_of(FaultKind::limit_data)[0].at, Time{10ms});
}

TEST(LimitData, CountsFragmentedPiecesAndDropsThePiecesAfterTheLimit) {
  Fragment f;
  f.piece_bytes = {4, 4};
  f.gap = {5ms, 5ms};
  const auto run =
      run_injector("raw", profile_of({rule(f), rule(LimitData{6})}), {{0ms, kTen}, {50ms, kTen}});
  const auto d = delivery_list(run);
  ASSERT_EQ(d.size(), 2U);
  EXPECT_EQ(bytes_of(d[0]), to_bytes("0123"));
  EXPECT_EQ(d[0].at, Time{0ms});
  EXPECT_EQ(bytes_of(d[1]), to_bytes("45"));
  EXPECT_EQ(d[1].at, Time{5ms});
  ASSERT_NE(run.link_break(), nullptr);
  EXPECT_EQ(run.outputs.back().at, Time{5ms});
}

TEST(LimitData, PacedByBandwidthTheCutWriteTakesOnlyItsOwnTime) {
  const auto run = run_injector("raw", profile_of({rule(Bandwidth{1000}), rule(LimitData{14})}),
                                {{0ms, kTen}, {0ms, kTen}});
  const auto d = delivery_list(run);
  ASSERT_EQ(d.size(), 2U);
  EXPECT_EQ(d[0].at, Time{10ms});
  EXPECT_EQ(d[1].at, Time{14ms}) << "4 bytes at 1000 B/s";
  EXPECT_EQ(run.outputs.back().at, Time{14ms});
}

TEST(LimitData, CountsOnlyInItsWindowAndDirection) {
  const auto later = rule(LimitData{15}, {}, TimeWindow{Time{1s}, std::nullopt});
  const auto run = run_injector("raw", profile_of({later}),
                                {{0ms, kTen}, {500ms, kTen}, {1s, kTen}, {1100ms, kTen}});
  EXPECT_EQ(run.delivered().size(), 35U) << "20 before the window, 15 in it";
  ASSERT_NE(run.link_break(), nullptr);
  EXPECT_EQ(run.outputs.back().at, Time{1100ms});

  auto other_way = rule(LimitData{1});
  other_way.direction = DirectionFilter::to_client;
  const auto untouched = run_injector("raw", profile_of({other_way}), {{0ms, kTen}});
  EXPECT_EQ(untouched.delivered(), kTen);
  EXPECT_EQ(untouched.link_break(), nullptr);
}

TEST(LimitData, ReplacingTheOtherRulesKeepsTheCountOfTheSameRule) {
  std::vector<FaultEvent> events;
  const auto limit = named(rule(LimitData{25}), "budget");
  auto injector = make_injector("raw", profile_of({limit}), events);
  std::vector<InjectorOutput> out;
  injector->push(Time{0ms}, kTen);
  injector->push(Time{10ms}, kTen);
  injector->set_profile(profile_of({rule(Delay{0ms, 0ms}), limit}));
  injector->push(Time{20ms}, kTen);
  injector->poll(Time{20ms}, out);
  Bytes delivered;
  for (const auto& o : out) {
    if (const auto* d = std::get_if<Delivery>(&o))
      delivered.insert(delivered.end(), d->bytes.begin(), d->bytes.end());
  }
  EXPECT_EQ(delivered.size(), 25U);
  ASSERT_TRUE(std::holds_alternative<LinkBreak>(out.back()));

  // A new rule (another limit) starts its own count.
  std::vector<FaultEvent> events2;
  auto fresh = make_injector("raw", profile_of({limit}), events2);
  fresh->push(Time{0ms}, kTen);
  fresh->push(Time{10ms}, kTen);
  fresh->set_profile(profile_of({named(rule(LimitData{26}), "budget")}));
  fresh->push(Time{20ms}, kTen);
  out.clear();
  fresh->poll(Time{20ms}, out);
  EXPECT_EQ(out.size(), 3U) << "30 bytes, no close";
  for (const auto& o : out)
    EXPECT_TRUE(std::holds_alternative<Delivery>(o));
}

TEST(LimitData, FramedByAProtocolItCountsTheFramesBytes) {
  const Bytes first = protocol::logi::encode(protocol::logi::SetSpeed{50});
  const Bytes second = protocol::logi::encode(protocol::logi::SetSpeed{60});
  const auto run = run_injector("logi", profile_of({rule(LimitData{first.size() + 3})}),
                                {{0ms, concat({first, second})}});
  EXPECT_EQ(run.delivered(), concat({first, Bytes(second.begin(), second.begin() + 3)}));
  ASSERT_NE(run.link_break(), nullptr);
  EXPECT_EQ(run.events_of(FaultKind::limit_data)[0].frame, 2U);
}

// ---------------------------------------------------------------- slow_close

TEST(SlowClose, TheEndOfTheStreamIsHeldForItsDelay) {
  std::vector<FaultEvent> events;
  auto injector = make_injector("raw", profile_of({rule(SlowClose{500ms})}), events);
  std::vector<InjectorOutput> out;
  injector->push(Time{0ms}, kTen);
  injector->poll(Time{0ms}, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(std::get<Delivery>(out[0]).bytes, kTen) << "bytes are not held";
  EXPECT_EQ(injector->next_due(), std::nullopt);

  injector->finish(Time{100ms});
  EXPECT_EQ(injector->next_due(), Time{600ms});
  out.clear();
  injector->poll(Time{599ms}, out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(injector->next_due(), Time{600ms});
  injector->poll(Time{600ms}, out);
  EXPECT_TRUE(out.empty()) << "the end is not an output: the link passes it on";
  EXPECT_EQ(injector->next_due(), std::nullopt);

  ASSERT_EQ(events.size(), 1U);
  EXPECT_EQ(events[0].kind, FaultKind::slow_close);
  EXPECT_EQ(events[0].at, Time{100ms});
  EXPECT_EQ(events[0].frame, 0U);
  EXPECT_EQ(events[0].detail, "sender closed; the close is passed on 500.000 ms later");
}

TEST(SlowClose, BytesDueLaterStillGoOutBeforeTheEnd) {
  std::vector<FaultEvent> events;
  auto injector =
      make_injector("raw", profile_of({rule(Delay{1s, 0ms}), rule(SlowClose{200ms})}), events);
  injector->push(Time{0ms}, kTen);
  injector->finish(Time{0ms});
  test::Run run;
  std::vector<Time> due;
  while (const auto next = injector->next_due()) {
    due.push_back(*next);
    std::vector<InjectorOutput> out;
    injector->poll(*next, out);
    for (auto& o : out)
      run.outputs.push_back(Output{*next, std::move(o)});
  }
  EXPECT_EQ(due, (std::vector<Time>{Time{200ms}, Time{1s}}));
  ASSERT_EQ(run.deliveries().size(), 1U);
  EXPECT_EQ(run.deliveries()[0].at, Time{1s});
}

TEST(SlowClose, WithoutTheRuleOrOutsideItsWindowTheEndPassesAtOnce) {
  std::vector<FaultEvent> events;
  auto plain = make_injector("raw", profile_of({rule(Delay{0ms, 0ms})}), events);
  plain->finish(Time{1s});
  EXPECT_EQ(plain->next_due(), std::nullopt);

  auto early = make_injector(
      "raw", profile_of({rule(SlowClose{500ms}, {}, TimeWindow{Time{0ms}, Time{1s}})}), events);
  early->finish(Time{2s});
  EXPECT_EQ(early->next_due(), std::nullopt);

  auto other = rule(SlowClose{500ms});
  other.direction = DirectionFilter::to_client;
  auto other_way = make_injector("raw", profile_of({other}), events);
  other_way->finish(Time{0ms});
  EXPECT_EQ(other_way->next_due(), std::nullopt);
  EXPECT_TRUE(events.empty());
}

TEST(SlowClose, NothingIsHeldAfterALimitClosedTheLink) {
  std::vector<FaultEvent> events;
  auto injector =
      make_injector("raw", profile_of({rule(LimitData{5}), rule(SlowClose{500ms})}), events);
  injector->push(Time{0ms}, kTen);
  std::vector<InjectorOutput> out;
  injector->poll(Time{0ms}, out);
  ASSERT_EQ(out.size(), 2U);
  injector->finish(Time{10ms});
  EXPECT_EQ(injector->next_due(), std::nullopt);
}

// ---------------------------------------------------------------- validation

TEST(StreamEndRules, ValidationRefusesTriggersAndBadValues) {
  EXPECT_EQ(rule_problem(rule(LimitData{0})), "'bytes' must be at least 1");
  EXPECT_EQ(rule_problem(rule(SlowClose{-1ms})), "'delay' must not be negative");
  Trigger first;
  first.first = 1;
  EXPECT_THAT(rule_problem(rule(LimitData{5}, first)).value_or(""),
              testing::HasSubstr("takes no trigger"));
  EXPECT_THAT(rule_problem(rule(SlowClose{5ms}, first)).value_or(""),
              testing::HasSubstr("takes no trigger"));
  EXPECT_EQ(rule_problem(rule(SlowClose{0ms})), std::nullopt);
  EXPECT_EQ(kFaultKindNames.size(), 14U);
  EXPECT_EQ(to_string(FaultKind::limit_data), "limit_data");
  EXPECT_EQ(parse_fault_kind("slow_close"), FaultKind::slow_close);
}

}  // namespace
}  // namespace hil::link
