// Toxiproxy's toxics as hil fault rules: the rule each type becomes, what a
// link under them delivers (virtual time, exact), the per-link toxicity
// draw, and the errors a bad toxic gets.

#include "control/toxic.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "tests/link/faults/fault_test_support.hpp"

namespace hil::control {
namespace {

using namespace std::chrono_literals;
using link::Direction;
using link::DirectionFilter;
using link::FaultProfile;
using link::FaultRule;
using link::Time;
using nlohmann::json;
using protocol::Bytes;
using protocol::to_bytes;
using testing::HasSubstr;
using testing::StartsWith;

const Bytes kTen = to_bytes("0123456789");

Toxic toxic(const std::string& body, Time now = Time{0}) {
  return parse_toxic(json::parse(body), now);
}

/// The one rule a toxic becomes on a link opened at `opened`.
FaultRule only_rule(const Toxic& t, Time opened = Time{0}) {
  const auto p = toxic_rules(t, opened);
  EXPECT_EQ(p.rules.size(), 1U);
  return p.rules.empty() ? FaultRule{} : p.rules[0];
}

/// The ApiError a body raises ("" when it is accepted).
std::string error_of(const std::string& body, int* status = nullptr) {
  try {
    parse_toxic(json::parse(body), Time{0});
  } catch (const ApiError& e) {
    if (status) *status = e.status();
    return e.what();
  }
  return "";
}

/// A to_client injector under the toxic's rules on a link opened at `opened`.
link::test::Run drive(const Toxic& t, const std::vector<link::test::Write>& writes,
                      Time opened = Time{0}, bool finish = false, Time drain_until = Time{10s}) {
  std::vector<link::FaultEvent> events;
  link::FaultInjector injector(
      t.stream, link::protocol_adapter("raw"), toxic_rules(t, opened), 7,
      [&events](const link::FaultEvent& e) { events.push_back(e); }, opened);
  auto run = link::test::drive(injector, writes, finish, drain_until);
  run.events = std::move(events);
  return run;
}

// ---------------------------------------------------------------- the toxic itself

TEST(Toxic, TypesAreToxiproxysThenHilsKindsWithoutRefuse) {
  const auto& types = toxic_types();
  const std::vector<std::string> toxiproxy = {"latency",    "bandwidth", "slow_close", "timeout",
                                              "reset_peer", "slicer",    "limit_data"};
  ASSERT_GE(types.size(), toxiproxy.size());
  EXPECT_EQ(std::vector<std::string>(types.begin(), types.begin() + 7), toxiproxy);
  for (const char* kind : {"fragment", "coalesce", "corrupt", "drop", "duplicate", "garbage",
                           "delay", "stall", "disconnect", "reset"}) {
    EXPECT_EQ(std::count(types.begin(), types.end(), kind), 1) << kind;
  }
  EXPECT_EQ(types.size(), 17U) << "7 of Toxiproxy's, 10 more of hil's, each once";
  EXPECT_EQ(std::count(types.begin(), types.end(), "refuse"), 0);
}

TEST(Toxic, DefaultsAreToxiproxys) {
  const Toxic t = toxic(R"({"type": "latency"})", Time{3s});
  EXPECT_EQ(t.name, "latency_downstream");
  EXPECT_EQ(t.stream, Direction::to_client);
  EXPECT_EQ(t.toxicity, 1.0);
  EXPECT_EQ(t.added_at, Time{3s});
  EXPECT_EQ(t.attributes, json::parse(R"({"latency": 0, "jitter": 0})"));
  EXPECT_EQ(to_json(t), json::parse(R"({"name": "latency_downstream", "type": "latency",
      "stream": "downstream", "toxicity": 1.0, "attributes": {"latency": 0, "jitter": 0}})"));

  const Toxic up = toxic(R"({"type": "slicer", "stream": "upstream", "name": "cut.1",
      "toxicity": 0.5, "attributes": {"average_size": 8}})");
  EXPECT_EQ(up.name, "cut.1");
  EXPECT_EQ(up.stream, Direction::to_car);
  EXPECT_EQ(up.toxicity, 0.5);
  EXPECT_EQ(up.attributes, json::parse(R"({"average_size": 8, "size_variation": 0, "delay": 0})"));
  EXPECT_EQ(toxic(R"({"type": "bandwidth", "stream": "upstream"})").name, "bandwidth_upstream");
}

TEST(Toxic, AnUpdateReplacesTheAttributesGivenAndKeepsTheRest) {
  const Toxic before =
      toxic(R"({"type": "latency", "attributes": {"latency": 100, "jitter": 10}})", Time{1s});
  const Toxic after = parse_toxic(
      json::parse(R"({"attributes": {"jitter": 20}, "toxicity": 0.25})"), Time{9s}, &before);
  EXPECT_EQ(after.attributes, json::parse(R"({"latency": 100, "jitter": 20})"));
  EXPECT_EQ(after.toxicity, 0.25);
  EXPECT_EQ(after.added_at, Time{1s}) << "the toxic keeps the time it was added";
  EXPECT_EQ(after.name, "latency_downstream");
  try {
    parse_toxic(json::parse(R"({"type": "bandwidth"})"), Time{9s}, &before);
    FAIL();
  } catch (const ApiError& e) {
    EXPECT_THAT(e.what(), StartsWith("type: a toxic's type cannot change"));
  }
}

// ---------------------------------------------------------------- the rules

TEST(ToxicRules, LatencyIsADelaySpanningLatencyPlusOrMinusJitter) {
  const FaultRule r = only_rule(
      toxic(R"({"type": "latency", "attributes": {"latency": 100, "jitter": 10}})", Time{2s}),
      Time{5s});
  EXPECT_EQ(r.action, link::FaultAction{(link::Delay{90ms, 20ms})});
  EXPECT_EQ(r.name, "toxic:latency_downstream");
  EXPECT_EQ(r.direction, DirectionFilter::to_client);
  EXPECT_EQ(r.window, (link::TimeWindow{Time{2s}, std::nullopt}));
  EXPECT_EQ(r.trigger, link::Trigger{});

  // More jitter than latency: never before now, up to latency + jitter.
  EXPECT_EQ(only_rule(toxic(R"({"type": "latency", "attributes": {"latency": 10, "jitter": 30}})"))
                .action,
            link::FaultAction{(link::Delay{0ms, 40ms})});
  EXPECT_TRUE(toxic_rules(toxic(R"({"type": "latency"})"), Time{0}).rules.empty())
      << "latency 0 does nothing";
}

TEST(ToxicRules, BandwidthSlowCloseSlicerAndLimitData) {
  EXPECT_EQ(only_rule(toxic(R"({"type": "bandwidth", "attributes": {"rate": 100}})")).action,
            link::FaultAction{link::Bandwidth{100'000}});
  EXPECT_TRUE(toxic_rules(toxic(R"({"type": "bandwidth"})"), Time{0}).rules.empty())
      << "rate 0 is no limit in Toxiproxy";
  EXPECT_EQ(only_rule(toxic(R"({"type": "slow_close", "attributes": {"delay": 500}})")).action,
            link::FaultAction{link::SlowClose{500ms}});
  EXPECT_EQ(only_rule(toxic(R"({"type": "slicer", "attributes":
                {"average_size": 10, "size_variation": 4, "delay": 500}})"))
                .action,
            link::FaultAction{(link::Fragment{{6, 14}, {500us, 500us}})});
  EXPECT_EQ(only_rule(toxic(R"({"type": "slicer", "attributes":
                {"average_size": 2, "size_variation": 5}})"))
                .action,
            link::FaultAction{(link::Fragment{{1, 7}, {0us, 0us}})});
  EXPECT_EQ(only_rule(toxic(R"({"type": "limit_data", "attributes": {"bytes": 64}})")).action,
            link::FaultAction{link::LimitData{64}});

  // bytes 0: Toxiproxy closes at the first write and lets nothing through.
  const auto zero = toxic_rules(toxic(R"({"type": "limit_data"})"), Time{0});
  ASSERT_EQ(zero.rules.size(), 2U);
  EXPECT_EQ(zero.rules[0].action, link::FaultAction{link::Drop{}});
  EXPECT_EQ(zero.rules[1].action, link::FaultAction{link::Disconnect{}});
  EXPECT_EQ(zero.rules[1].trigger.first, 1U);
}

TEST(ToxicRules, TimedToxicsCountFromTheLaterOfAddedAndOpened) {
  const Toxic timeout = toxic(
      R"({"type": "timeout", "stream": "upstream", "attributes": {"timeout": 1000}})", Time{2s});
  const auto on_new_link = toxic_rules(timeout, Time{5s});
  ASSERT_EQ(on_new_link.rules.size(), 2U);
  EXPECT_EQ(on_new_link.rules[0].action, link::FaultAction{link::Drop{}});
  EXPECT_EQ(on_new_link.rules[0].trigger, link::Trigger{}) << "every frame";
  EXPECT_EQ(on_new_link.rules[0].direction, DirectionFilter::to_car);
  EXPECT_EQ(on_new_link.rules[1].action, link::FaultAction{link::Disconnect{}});
  EXPECT_EQ(on_new_link.rules[1].trigger.at, Time{6s});
  EXPECT_EQ(on_new_link.rules[1].name, "toxic:timeout_upstream");
  EXPECT_EQ(toxic_rules(timeout, Time{1s}).rules[1].trigger.at, Time{3s})
      << "a link already open when the toxic was added";
  EXPECT_EQ(toxic_rules(toxic(R"({"type": "timeout"})"), Time{0}).rules.size(), 1U)
      << "timeout 0 never closes";

  const auto reset = only_rule(
      toxic(R"({"type": "reset_peer", "attributes": {"timeout": 200}})", Time{1s}), Time{4s});
  EXPECT_EQ(reset.action, link::FaultAction{link::Reset{}});
  EXPECT_EQ(reset.trigger.at, Time{4200ms});
}

TEST(ToxicRules, HilKindsTakeTheirYamlKeysAsAttributes) {
  const FaultRule corrupt = only_rule(toxic(R"({"type": "corrupt", "stream": "upstream",
      "attributes": {"target": "checksum", "match": "STAT", "every": 8}})"));
  link::Corrupt want;
  want.target = link::CorruptTarget::checksum;
  EXPECT_EQ(corrupt.action, link::FaultAction{want});
  EXPECT_EQ(corrupt.trigger.match, "STAT");
  EXPECT_EQ(corrupt.trigger.every, 8U);
  EXPECT_EQ(corrupt.direction, DirectionFilter::to_car);
  EXPECT_EQ(corrupt.name, "toxic:corrupt_upstream");

  const FaultRule fragment = only_rule(toxic(R"({"type": "fragment",
      "attributes": {"sizes": [1, 4], "gap": ["0ms", "5ms"], "probability": 0.5}})"));
  EXPECT_EQ(fragment.action, link::FaultAction{(link::Fragment{{1, 4}, {0ms, 5ms}})});
  EXPECT_EQ(fragment.trigger.probability, 0.5);

  // Windows count from when the toxic was added, `at` from when it starts on the link.
  const FaultRule drop =
      only_rule(toxic(R"({"type": "drop", "attributes": {"from": "1s", "to": "2s"}})", Time{10s}));
  EXPECT_EQ(drop.window, (link::TimeWindow{Time{11s}, Time{12s}}));
  const FaultRule stall = only_rule(
      toxic(R"({"type": "stall", "attributes": {"at": "1s", "for": "2s"}})", Time{10s}), Time{12s});
  EXPECT_EQ(stall.trigger.at, Time{13s});
  EXPECT_EQ(stall.window.from, Time{10s});
  EXPECT_EQ(stall.action, link::FaultAction{link::Stall{2s}});

  // The kinds whose names Toxiproxy shares take hil's keys as well.
  EXPECT_EQ(only_rule(toxic(R"({"type": "bandwidth", "attributes": {"baud": 9600}})")).action,
            link::FaultAction{link::Bandwidth{960}});
  EXPECT_EQ(only_rule(toxic(R"({"type": "slow_close", "attributes": {"delay": "250ms"}})")).action,
            link::FaultAction{link::SlowClose{250ms}});
  const FaultRule limit = only_rule(
      toxic(R"({"type": "limit_data", "attributes": {"bytes": 9, "from": "1s"}})", Time{1s}));
  EXPECT_EQ(limit.action, link::FaultAction{link::LimitData{9}});
  EXPECT_EQ(limit.window.from, Time{2s});
}

// ---------------------------------------------------------------- links under toxics

TEST(ToxicOnALink, LatencyDelaysEachWriteExactlyWithoutJitter) {
  const auto run = drive(toxic(R"({"type": "latency", "attributes": {"latency": 100}})"),
                         {{0ms, kTen}, {30ms, kTen}});
  const auto d = run.deliveries();
  ASSERT_EQ(d.size(), 2U);
  EXPECT_EQ(d[0].at, Time{100ms});
  EXPECT_EQ(d[1].at, Time{130ms});
  EXPECT_EQ(run.delivered(), link::test::concat({kTen, kTen}));
}

TEST(ToxicOnALink, LatencyWithJitterStaysWithinLatencyPlusOrMinusJitter) {
  std::vector<link::test::Write> writes;
  for (int i = 0; i < 50; ++i)
    writes.push_back({Time{1s} * i, kTen});  // far apart: no write holds back another
  const auto run =
      drive(toxic(R"({"type": "latency", "attributes": {"latency": 100, "jitter": 20}})"), writes,
            Time{0}, false, Time{100s});
  const auto d = run.deliveries();
  ASSERT_EQ(d.size(), 50U);
  bool below = false;
  bool above = false;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const auto late = d[i].at - writes[i].at;
    EXPECT_GE(late, 80ms);
    EXPECT_LE(late, 120ms);
    below = below || late < 100ms;
    above = above || late > 100ms;
  }
  EXPECT_TRUE(below && above) << "jitter goes both ways around the latency";
}

TEST(ToxicOnALink, BandwidthPacesAtRateKilobytesPerSecond) {
  const auto run = drive(toxic(R"({"type": "bandwidth", "attributes": {"rate": 1}})"),
                         {{0ms, kTen}, {0ms, kTen}, {50ms, kTen}});
  const auto d = run.deliveries();
  ASSERT_EQ(d.size(), 3U);
  EXPECT_EQ(d[0].at, Time{10ms}) << "10 bytes at 1000 B/s";
  EXPECT_EQ(d[1].at, Time{20ms});
  EXPECT_EQ(d[2].at, Time{60ms});
}

TEST(ToxicOnALink, SlicerCutsWritesIntoPiecesDelayApart) {
  const auto run = drive(toxic(R"({"type": "slicer", "attributes":
      {"average_size": 4, "size_variation": 0, "delay": 1000}})"),
                         {{0ms, kTen}});
  const auto d = run.deliveries();
  ASSERT_EQ(d.size(), 3U);
  EXPECT_EQ(std::get<link::Delivery>(d[0].what).bytes, to_bytes("0123"));
  EXPECT_EQ(std::get<link::Delivery>(d[1].what).bytes, to_bytes("4567"));
  EXPECT_EQ(std::get<link::Delivery>(d[2].what).bytes, to_bytes("89"));
  EXPECT_EQ(d[0].at, Time{0ms});
  EXPECT_EQ(d[1].at, Time{1ms});
  EXPECT_EQ(d[2].at, Time{2ms});
}

TEST(ToxicOnALink, LimitDataLetsTheBytesThroughThenClosesGracefully) {
  const auto run = drive(toxic(R"({"type": "limit_data", "attributes": {"bytes": 15}})"),
                         {{0ms, kTen}, {10ms, kTen}, {20ms, kTen}});
  EXPECT_EQ(run.delivered(), to_bytes("012345678901234"));
  ASSERT_NE(run.link_break(), nullptr);
  EXPECT_FALSE(run.link_break()->reset);
  EXPECT_EQ(run.outputs.back().at, Time{10ms});
  ASSERT_EQ(run.events.size(), 1U);
  EXPECT_EQ(run.events[0].rule, "toxic:limit_data_downstream");
}

TEST(ToxicOnALink, TimeoutPassesNothingAndClosesAfterTheTimeout) {
  const auto run = drive(toxic(R"({"type": "timeout", "attributes": {"timeout": 1000}})", Time{2s}),
                         {{2s, kTen}, {2500ms, kTen}}, Time{1s});
  EXPECT_TRUE(run.deliveries().empty());
  ASSERT_EQ(run.outputs.size(), 1U);
  ASSERT_NE(run.link_break(), nullptr);
  EXPECT_FALSE(run.link_break()->reset);
  EXPECT_EQ(run.outputs[0].at, Time{3s});

  const auto never = drive(toxic(R"({"type": "timeout"})"), {{0ms, kTen}});
  EXPECT_TRUE(never.outputs.empty()) << "timeout 0 holds the link open, passing nothing";
}

TEST(ToxicOnALink, ResetPeerResetsTheTimeoutAfterTheLinkOpened) {
  const auto run = drive(toxic(R"({"type": "reset_peer", "attributes": {"timeout": 200}})"),
                         {{1s, kTen}, {1100ms, kTen}, {1300ms, kTen}}, Time{1s});
  ASSERT_EQ(run.deliveries().size(), 2U);
  EXPECT_EQ(run.delivered(), link::test::concat({kTen, kTen}));
  ASSERT_NE(run.link_break(), nullptr);
  EXPECT_TRUE(run.link_break()->reset);
  EXPECT_EQ(run.outputs.back().at, Time{1200ms});
}

TEST(ToxicOnALink, AddedWhileTheLinkIsOpenItActsFromThen) {
  link::FaultInjector injector(Direction::to_client, link::protocol_adapter("raw"), {}, 1);
  std::vector<link::InjectorOutput> out;
  injector.push(Time{500ms}, kTen);
  injector.poll(Time{500ms}, out);
  ASSERT_EQ(out.size(), 1U);

  const Toxic t = toxic(R"({"type": "latency", "attributes": {"latency": 300}})", Time{1s});
  injector.set_profile(toxic_rules(t, Time{0}));
  injector.push(Time{1s}, kTen);
  out.clear();
  injector.poll(Time{1s}, out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(injector.next_due(), Time{1300ms});
  injector.poll(Time{1300ms}, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(std::get<link::Delivery>(out[0]).bytes, kTen);
}

TEST(ToxicOnALink, SlowCloseHoldsTheEndOfTheStream) {
  const Toxic t = toxic(R"({"type": "slow_close", "attributes": {"delay": 300}})");
  link::FaultInjector injector(t.stream, link::protocol_adapter("raw"), toxic_rules(t, Time{0}), 1);
  injector.finish(Time{1s});
  EXPECT_EQ(injector.next_due(), Time{1300ms});
}

// ---------------------------------------------------------------- toxicity

TEST(Toxicity, ActsOnAboutThatShareOfLinksTheSameForTheSameSeed) {
  Toxic t = toxic(R"({"type": "latency", "toxicity": 0.3})");
  int acting = 0;
  for (std::uint64_t seed = 0; seed < 1000; ++seed) {
    if (acts_on_link(t, seed)) ++acting;
    EXPECT_EQ(acts_on_link(t, seed), acts_on_link(t, seed));
  }
  EXPECT_GE(acting, 250);
  EXPECT_LE(acting, 350);

  Toxic other = t;
  other.name = "another";
  int differ = 0;
  for (std::uint64_t seed = 0; seed < 1000; ++seed) {
    if (acts_on_link(t, seed) != acts_on_link(other, seed)) ++differ;
  }
  EXPECT_GT(differ, 200) << "each toxic draws for itself";

  t.toxicity = 1.0;
  other.toxicity = 0.0;
  for (std::uint64_t seed = 0; seed < 1000; ++seed) {
    EXPECT_TRUE(acts_on_link(t, seed));
    EXPECT_FALSE(acts_on_link(other, seed));
  }
}

// ---------------------------------------------------------------- errors

TEST(ToxicErrors, EachNamesItsField) {
  struct Case {
    std::string body;
    std::string starts;
    std::string also = {};
  };
  const std::vector<Case> cases = {
      {R"([1])", "body: got a list"},
      {R"({})", "type: missing", "latency"},
      {R"({"type": "latancy"})", "type: unknown type 'latancy'", "limit_data"},
      {R"({"type": "refuse"})", "type: unknown type 'refuse'"},
      {R"({"type": 3})", "type: got a number"},
      {R"({"type": "latency", "colour": 1})", "colour: unknown field"},
      {R"({"type": "latency", "direction": "upstream"})", "direction: ", "stream"},
      {R"({"type": "latency", "stream": "up"})", "stream: 'up' is not a stream", "upstream"},
      {R"({"type": "latency", "stream": 1})", "stream: a number is not a stream"},
      {R"({"type": "latency", "toxicity": 1.5})", "toxicity: 1.5 is outside [0, 1]"},
      {R"({"type": "latency", "toxicity": -0.1})", "toxicity: -0.1 is outside [0, 1]"},
      {R"({"type": "latency", "toxicity": "1"})", "toxicity: got a string"},
      {R"({"type": "latency", "name": ""})", "name: is empty"},
      {R"({"type": "latency", "name": "a b"})", "name: 'a b' holds a character"},
      {R"({"type": "latency", "name": 5})", "name: got a number"},
      {R"({"type": "latency", "attributes": [1]})", "attributes: got a list"},
      {R"({"type": "latency", "attributes": {"latency": -5}})",
       "attributes.latency: -5 is negative (expected milliseconds"},
      {R"({"type": "latency", "attributes": {"latency": "100"}})",
       "attributes.latency: got a string (expected milliseconds"},
      {R"({"type": "latency", "attributes": {"latency": 1.5}})",
       "attributes.latency: 1.5 is not whole"},
      {R"({"type": "latency", "attributes": {"latenzy": 5}})",
       "attributes.latenzy: unknown attribute of a latency toxic (known: latency, jitter)"},
      {R"({"type": "bandwidth", "attributes": {"rate": 100000000000}})",
       "attributes.rate: 100000000000 is too large"},
      {R"({"type": "bandwidth", "attributes": {"rate": 1, "baud": 9600}})",
       "attributes.rate: Toxiproxy's 'rate' does not go with hil's baud"},
      {R"({"type": "bandwidth", "attributes": {"rat": 1}})",
       "attributes.rat: unknown attribute of a bandwidth toxic (known: rate, baud, "
       "bytes_per_second"},
      {R"({"type": "corrupt", "attributes": {"direction": "to_car"}})",
       "attributes.direction: ", "stream"},
      {R"({"type": "corrupt", "attributes": {"bits": 0}})",
       "attributes.bits: 'bits' must be a whole number >= 1"},
      {R"({"type": "corrupt", "attributes": {"every": "8"}})", "attributes.every: got a string"},
      {R"({"type": "corrupt", "attributes": {"frist": 1}})",
       "attributes.frist: unknown attribute of a corrupt toxic", "first"},
      {R"({"type": "delay", "attributes": {"delay": 100}})",
       "attributes.delay: got a number (expected a duration"},
      {R"({"type": "delay", "attributes": {"delay": "100"}})",
       "attributes.delay: 'delay' must be a duration with a unit"},
      {R"({"type": "delay"})", "attributes: 'delay' is missing"},
      {R"({"type": "drop", "attributes": {"probability": 1.5}})",
       "attributes.probability: 'probability' must be a number in [0, 1]"},
      {R"({"type": "drop", "attributes": {"match": null}})", "attributes.match: got null"},
      {R"({"type": "fragment", "attributes": {"sizes": [4, "x"]}})",
       "attributes.sizes: got a list holding a string"},
      {R"({"type": "fragment", "attributes": {"sizes": [5, 2]}})",
       "attributes.sizes: 'sizes' must be"},
      {R"({"type": "stall", "attributes": {"for": "1s"}})",
       "attributes: needs 'at' or a frame trigger"},
      {R"({"type": "drop", "attributes": {"from": "2s", "to": "1s"}})",
       "attributes.to: 'to' must be after 'from'"},
      {R"({"type": "limit_data", "attributes": {"bytes": 0, "to": "1s"}})",
       "attributes.bytes: 'bytes' must be a whole number >= 1"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.body);
    int status = 0;
    const std::string error = error_of(c.body, &status);
    EXPECT_THAT(error, StartsWith(c.starts));
    if (!c.also.empty()) EXPECT_THAT(error, HasSubstr(c.also));
    EXPECT_EQ(status, 400);
  }
}

}  // namespace
}  // namespace hil::control
