// The expectation checker on timelines built by hand: what matches and where
// a window lies (what each quantifier accepts and what a failure tells the
// QA engineer who reads it: expect_quantifiers_test.cpp).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "harness/expect.hpp"
#include "harness/scenario_yaml.hpp"
#include "tests/harness/expect_support.hpp"

namespace hil::harness {
namespace {

using namespace test;

/// A `fields:` matcher text and whether the record holds it.
struct FieldsCase {
  std::string fields;
  bool holds;
};

/// Expects each case of `holds` (a record's answer to a `fields:` text).
template <class Holds>
void expect_fields(const std::vector<FieldsCase>& cases, Holds&& holds) {
  for (const auto& c : cases) {
    SCOPED_TRACE(c.fields);
    EXPECT_EQ(holds(c.fields), c.holds);
  }
}

// ------------------------------------------------------------------ matches

TEST(ExpectMatches, NeedsTheSourceAndTheKindUnlessTheKindIsEmpty) {
  const Record r{ms(1), ClientKind::stale, {}};
  EXPECT_TRUE(matches(Matcher{Source::client, ClientKind::stale, {}, ""}, r));
  EXPECT_TRUE(matches(Matcher{Source::client, std::nullopt, {}, ""}, r));
  EXPECT_FALSE(matches(Matcher{Source::client, ClientKind::notice, {}, ""}, r));
  EXPECT_FALSE(matches(Matcher{Source::wire, std::nullopt, {}, ""}, r));
}

TEST(ExpectMatches, EqualsComparesNumbersByValueAndNothingElseAcrossTypes) {
  const Record r = record_with({{"station", 2}, {"name", "2"}, {"on", true}});
  const auto holds = [&](FieldTest t) {
    return matches(Matcher{Source::sim, std::nullopt, {t}, ""}, r);
  };
  EXPECT_TRUE(holds(test_of("station", Op::equals, 2.0)));
  EXPECT_TRUE(holds(test_of("station", Op::equals, 2u)));
  EXPECT_FALSE(holds(test_of("station", Op::equals, 3)));
  EXPECT_FALSE(holds(test_of("station", Op::equals, "2")));
  EXPECT_FALSE(holds(test_of("name", Op::equals, 2)));
  EXPECT_TRUE(holds(test_of("name", Op::equals, "2")));
  EXPECT_TRUE(holds(test_of("on", Op::equals, true)));
  EXPECT_FALSE(holds(test_of("on", Op::equals, 1)));
  EXPECT_TRUE(holds(test_of("station", Op::not_equals, 2.5)));
  EXPECT_FALSE(holds(test_of("station", Op::not_equals, 2.0)));
}

TEST(ExpectMatches, AMissingFieldFailsEveryTestExceptNotEquals) {
  const Record r = record_with({{"speed_mps", 0.0}});
  for (const Op op : {Op::equals, Op::kind_prefix, Op::contains, Op::less, Op::less_equal,
                      Op::greater, Op::greater_equal}) {
    EXPECT_FALSE(matches(Matcher{Source::sim, std::nullopt, {test_of("station", op, 1)}, ""}, r))
        << static_cast<int>(op);
  }
  EXPECT_TRUE(
      matches(Matcher{Source::sim, std::nullopt, {test_of("station", Op::not_equals, 1)}, ""}, r));
}

TEST(ExpectMatches, KindPrefixMatchesWholePartsOnly) {
  const auto received = [](const std::string& frame) {
    return matches(car_received("MV"),
                   Record{ms(0), WireKind::frame, frame_data("to_car", "delivered", frame)});
  };
  EXPECT_TRUE(received("MV"));
  EXPECT_TRUE(received("MV:STOP"));
  EXPECT_TRUE(received("MV.FWD"));
  EXPECT_FALSE(received("MVX"));
  EXPECT_FALSE(received("ST:MV"));
  // The direction and stage still count.
  EXPECT_FALSE(matches(car_received("MV"),
                       Record{ms(0), WireKind::frame, frame_data("to_car", "sent", "MV:STOP")}));
}

/// The first expectation's matcher of a LOGI scenario whose expect list is `expectation`.
Matcher loaded(const std::string& expectation, const std::string& car = "logi") {
  const auto s = parse_scenario_text("name: t\ncar: " + car + "\nsteps: [" +
                                         (car == "arduino" ? "PING" : "connect") +
                                         "]\nexpect:\n  - " + expectation + "\n",
                                     "t.yaml");
  return s.expectations.at(0).what;
}

Record frame_record(const std::string& dir, const std::string& stage, nlohmann::json data) {
  data["dir"] = dir;
  data["stage"] = stage;
  return Record{ms(0), WireKind::frame, std::move(data)};
}

TEST(ExpectMatches, ADamagedFrameNamedOnlyAsFarAsTheDecoderGotCountsAsInvalidOfTheKind) {
  const Matcher wanted = loaded("{received_by_client: \"FB:SP\", valid: false}");
  const auto invalid = [](const std::string& kind) {
    return frame_record("to_client", "delivered",
                        {{"frame", kind}, {"valid", false}, {"error", "bad_checksum"}});
  };
  EXPECT_TRUE(matches(wanted, invalid("FB")));     // the decoder stopped at the code
  EXPECT_TRUE(matches(wanted, invalid("FB:SP")));  // or got the whole kind
  EXPECT_FALSE(matches(wanted, invalid("FB:ST")));
  EXPECT_FALSE(matches(wanted, invalid("F")));  // whole parts only
  EXPECT_FALSE(matches(wanted, invalid("")));   // garbage names nothing
  EXPECT_FALSE(matches(wanted, invalid("STAT")));
  // A valid FB is not what was asked for.
  EXPECT_FALSE(matches(
      wanted, frame_record("to_client", "delivered", {{"frame", "FB:MV"}, {"valid", true}})));
  // Without valid: false a frame must be named in full: a damaged "FB" could
  // have been any feedback, so it is no FB:SP the client received.
  EXPECT_FALSE(matches(loaded("{received_by_client: \"FB:SP\"}"), invalid("FB")));
}

TEST(ExpectMatches, TextIsTheWholeFrameOrASubstringOfIt) {
  const Record sp30 = frame_record("to_car", "delivered",
                                   {{"frame", "SP"}, {"valid", true}, {"text", "LOGI:SP:030:D5#"}});
  EXPECT_TRUE(matches(loaded("{received: SP, text: \"LOGI:SP:030:D5#\"}"), sp30));
  EXPECT_FALSE(matches(loaded("{received: SP, text: \"SP:030\"}"), sp30));
  EXPECT_TRUE(matches(loaded("{received: SP, text: {contains: \"SP:030\"}}"), sp30));
  EXPECT_FALSE(matches(loaded("{received: SP, text: {contains: \"SP:050\"}}"), sp30));
}

TEST(ExpectMatches, HexIsComparedInTheTimelinesSpellingWhateverTheScenarioWrote) {
  const Record data = frame_record("to_client", "delivered",
                                   {{"frame", "DATA"}, {"valid", true}, {"hex", "06 02 64 00"}});
  EXPECT_TRUE(matches(loaded("{received_by_client: DATA, hex: \"06026400\"}", "wr8"), data));
  EXPECT_TRUE(
      matches(loaded("{received_by_client: DATA, hex: {contains: \"02 64\"}}", "wr8"), data));
  EXPECT_TRUE(
      matches(loaded("{received_by_client: DATA, hex: {contains: \"0264\"}}", "wr8"), data));
  EXPECT_FALSE(
      matches(loaded("{received_by_client: DATA, hex: {contains: \"64 01\"}}", "wr8"), data));
}

TEST(ExpectMatches, MessageIsASubstringOfTheDecodedMessage) {
  const Record fb =
      frame_record("to_client", "delivered",
                   {{"frame", "FB:MV"}, {"valid", true}, {"message", "Feedback MV rejected"}});
  EXPECT_TRUE(matches(loaded("{received_by_client: \"FB:MV\", message: rejected}"), fb));
  EXPECT_FALSE(matches(loaded("{received_by_client: \"FB:MV\", message: accepted}"), fb));
}

TEST(ExpectMatches, FieldsCompareEachDecodedFieldByValueOrRange) {
  const Record data =
      frame_record("to_client", "delivered",
                   {{"frame", "DATA"},
                    {"valid", true},
                    {"fields", {{"state", "RUN"}, {"speed_mps", 0.3}, {"odometry_cm", 12}}}});
  const auto holds = [&](const std::string& fields) {
    return matches(loaded("{received_by_client: DATA, fields: " + fields + "}", "wr8"), data);
  };
  expect_fields(
      {
          {"{state: RUN}", true},
          {"{state: RUN, odometry_cm: 12}", true},
          {"{odometry_cm: 12.0}", true},  // a number is a number however it is written
          {"{state: STOP}", false},
          {"{state: RUN, odometry_cm: 13}", false},  // every field must hold
          {"{speed_mps: {at_least: 0.3, below: 0.5}}", true},
          {"{speed_mps: {above: 0.3}}", false},
          {"{speed_mps: {at_most: 0.29}}", false},
          {"{state: {not: STOP}}", true},
          {"{state: {contains: RU}}", true},
          // A field the frame does not have holds only a 'not'.
          {"{battery_percent: 100}", false},
          {"{battery_percent: {not: 100}}", true},
      },
      holds);
}

TEST(ExpectMatches, AFieldWithLeadingZerosIsTextAndMatchesOnlyItsOwnDigits) {
  const Record stat = frame_record(
      "to_client", "delivered",
      {{"frame", "STAT"}, {"valid", true}, {"fields", {{"track", "0110"}, {"station", 2}}}});
  const auto holds = [&](const std::string& fields) {
    return matches(loaded("{received_by_client: STAT, fields: " + fields + "}"), stat);
  };
  expect_fields({{"{track: 0110}", true},
                 {"{track: \"0110\"}", true},
                 {"{track: 110}", false},
                 {"{station: 2}", true},
                 {"{station: \"002\"}", false}},
                holds);
}

TEST(ExpectMatches, AFieldPathWalksIntoObjectsAndAFailureShowsWhatTheRecordHad) {
  const Record r{ms(0), WireKind::frame, {{"fields", {{"percent", 30}}}}};
  EXPECT_TRUE(matches(
      Matcher{Source::wire, std::nullopt, {test_of("fields.percent", Op::equals, 30)}, ""}, r));
  EXPECT_FALSE(matches(
      Matcher{Source::wire, std::nullopt, {test_of("fields.percent.x", Op::equals, 30)}, ""}, r));
  EXPECT_FALSE(matches(
      Matcher{Source::wire, std::nullopt, {test_of("fields.speed", Op::equals, 30)}, ""}, r));

  Timeline t;
  t.add(r);
  Expectation e;
  e.what = Matcher{Source::wire, WireKind::frame, {test_of("fields.percent", Op::greater, 50)}, ""};
  e.quantifier = Quantifier::always;
  const auto outcome = check(e, t, ms(100));
  EXPECT_FALSE(outcome.passed);
  EXPECT_NE(outcome.message.find("fields.percent = 30"), std::string::npos) << outcome.message;
}

TEST(ExpectAlwaysOnFrames, JudgesOnlyTheFramesOfTheDirectionStageAndKindAsked) {
  Timeline t;
  const auto stat = [&](Time at, const std::string& dir, const std::string& stage,
                        const std::string& mode) {
    t.add(at, WireKind::frame,
          {{"dir", dir},
           {"stage", stage},
           {"frame", "STAT"},
           {"valid", true},
           {"fields", {{"mode", mode}}}});
  };
  stat(ms(500), "to_client", "sent", "MAN");
  stat(ms(500), "to_client", "delivered", "MAN");
  t.add(ms(600), WireKind::frame,
        {{"dir", "to_car"}, {"stage", "delivered"}, {"frame", "MD:AUTO"}, {"valid", true}});
  stat(ms(1000), "to_client", "sent", "AUTO");  // sent, but lost on the way
  stat(ms(1500), "to_client", "delivered", "MAN");
  Expectation e;
  e.what = loaded("{received_by_client: STAT, fields: {mode: MAN}}");
  e.quantifier = Quantifier::always;
  const auto outcome = check(e, t, ms(2000));
  EXPECT_TRUE(outcome.passed) << outcome.message;
  EXPECT_NE(outcome.message.find("all 2 did"), std::string::npos) << outcome.message;

  stat(ms(1800), "to_client", "delivered", "AUTO");
  const auto failed = check(e, t, ms(2000));
  EXPECT_FALSE(failed.passed);
  EXPECT_NE(
      failed.message.find("1 of 3 did not: at 1.800 s (the first had fields.mode = \"AUTO\")"),
      std::string::npos)
      << failed.message;
}

TEST(ExpectMatches, TheFieldKindTestsTheRecordsKind) {
  const Record r{ms(0), link::FaultKind::drop, {{"dir", "to_car"}}};
  const auto kind_is = [&](Op op, const char* word) {
    return matches(Matcher{Source::fault, std::nullopt, {test_of("kind", op, word)}, ""}, r);
  };
  EXPECT_TRUE(kind_is(Op::kind_prefix, "drop"));
  EXPECT_TRUE(kind_is(Op::equals, "drop"));
  EXPECT_FALSE(kind_is(Op::equals, "corrupt"));
  EXPECT_FALSE(kind_is(Op::kind_prefix, "dup"));
}

TEST(ExpectMatches, ContainsLooksForASubstringOfAString) {
  const Record r{ms(0), ClientKind::notice, {{"text", "Not in manual mode"}, {"n", 12}}};
  const auto holds = [&](FieldTest t) {
    return matches(Matcher{Source::client, std::nullopt, {t}, ""}, r);
  };
  EXPECT_TRUE(holds(test_of("text", Op::contains, "manual")));
  EXPECT_TRUE(holds(test_of("text", Op::contains, "Not in manual mode")));
  EXPECT_FALSE(holds(test_of("text", Op::contains, "Manual")));
  EXPECT_FALSE(holds(test_of("n", Op::contains, "1")));
}

TEST(ExpectMatches, OrderingTestsCompareNumbersAtTheirBoundaries) {
  const Record r = record_with({{"speed_mps", 0.5}, {"label", "fast"}});
  const auto holds = [&](Op op, nlohmann::json v) {
    return matches(
        Matcher{Source::sim, SimKind::sample, {test_of("speed_mps", op, std::move(v))}, ""}, r);
  };
  EXPECT_TRUE(holds(Op::less, 0.6));
  EXPECT_FALSE(holds(Op::less, 0.5));
  EXPECT_TRUE(holds(Op::less_equal, 0.5));
  EXPECT_FALSE(holds(Op::less_equal, 0.4));
  EXPECT_TRUE(holds(Op::greater, 0));
  EXPECT_FALSE(holds(Op::greater, 0.5));
  EXPECT_TRUE(holds(Op::greater_equal, 0.5));
  EXPECT_FALSE(holds(Op::greater_equal, 1));
  EXPECT_FALSE(holds(Op::less, "1"));
  EXPECT_FALSE(
      matches(Matcher{Source::sim, SimKind::sample, {test_of("label", Op::less, 1)}, ""}, r));
}

TEST(ExpectMatches, EveryTestMustHold) {
  const Record r{ms(0), WireKind::frame, frame_data("to_client", "delivered", "MV:STOP")};
  EXPECT_FALSE(matches(car_received("MV:STOP"), r));
  EXPECT_TRUE(matches(
      Matcher{Source::wire, WireKind::frame, {test_of("frame", Op::equals, "MV:STOP")}, ""}, r));
}

// ------------------------------------------------------------------ resolve

class ExpectResolve : public ::testing::Test {
 protected:
  void SetUp() override {
    // One step a second: press FWD, release, press FWD, release, release.
    int second = 0;
    for (const char* step : {"press FWD", "release", "press FWD", "release", "release"})
      add_step_end(t_, ms(1000 * ++second), step);
  }
  Timeline t_;
};

TEST_F(ExpectResolve, WithoutAnEventIsTheStartMovedByTheOffset) {
  EXPECT_EQ(resolve(Anchor{}, t_), ms(0));
  EXPECT_EQ(resolve(Anchor{std::nullopt, 1, seconds(5)}, t_), ms(5000));
}

TEST_F(ExpectResolve, PicksTheFirstSecondOrLastMatchAndAddsTheOffset) {
  EXPECT_EQ(resolve(Anchor{step_end("release"), 1, {}}, t_), ms(2000));
  EXPECT_EQ(resolve(Anchor{step_end("release"), 2, {}}, t_), ms(4000));
  EXPECT_EQ(resolve(Anchor{step_end("release"), -1, {}}, t_), ms(5000));
  EXPECT_EQ(resolve(Anchor{step_end("release"), -3, {}}, t_), ms(2000));
  EXPECT_EQ(resolve(Anchor{step_end("release"), 2, milliseconds(250)}, t_), ms(4250));
  EXPECT_EQ(resolve(Anchor{step_end("press FWD"), -1, milliseconds(-500)}, t_), ms(2500));
}

TEST_F(ExpectResolve, IsNothingWhenTheEventOrItsOccurrenceNeverHappened) {
  EXPECT_EQ(resolve(Anchor{step_end("estop"), 1, {}}, t_), std::nullopt);
  EXPECT_EQ(resolve(Anchor{step_end("release"), 4, {}}, t_), std::nullopt);
  EXPECT_EQ(resolve(Anchor{step_end("release"), -4, {}}, t_), std::nullopt);
  EXPECT_EQ(resolve(Anchor{step_end("release"), 0, {}}, t_), std::nullopt);
}

// ------------------------------------------------------------------- window

TEST(ExpectWindow, IncludesBothEndsAndNothingANanosecondBeyond) {
  const Expectation e = stop_within_300ms_of_release();
  const auto at_edge = check(e, release_then_stop(ms(1300)), ms(10000));
  EXPECT_TRUE(at_edge.passed) << at_edge.message;
  EXPECT_EQ(at_edge.window_from, ms(1000));
  EXPECT_EQ(at_edge.window_to, ms(1300));

  EXPECT_FALSE(check(e, release_then_stop(ms(1300) + nanoseconds(1)), ms(10000)).passed);

  Timeline at_start;
  add_delivered(at_start, ms(1000), "MV:STOP");
  add_step_end(at_start, ms(1000), "release");
  EXPECT_TRUE(check(e, at_start, ms(10000)).passed);

  Timeline early;
  early.add(ms(1000) - nanoseconds(1), WireKind::frame,
            frame_data("to_car", "delivered", "MV:STOP"));
  add_step_end(early, ms(1000), "release");
  EXPECT_FALSE(check(e, early, ms(10000)).passed);
}

TEST(ExpectWindow, WithoutWithinRunsToTheEndOfTheRun) {
  Timeline t;
  add_delivered(t, ms(9000), "MV:STOP");
  const Expectation e = expect_in(car_received("MV:STOP"), whole_run());
  const auto ended_after = check(e, t, ms(9000));
  EXPECT_TRUE(ended_after.passed);
  EXPECT_EQ(ended_after.window_from, ms(0));
  EXPECT_EQ(ended_after.window_to, ms(9000));
  EXPECT_FALSE(check(e, t, ms(8999)).passed);
}

TEST(ExpectWindow, AMissingAnchorFailsAndSaysWhichOne) {
  Timeline t;
  add_step_end(t, ms(1000), "press FWD");
  add_delivered(t, ms(1100), "MV:STOP");
  const Expectation e = stop_within_300ms_of_release();
  const auto o = check(e, t, ms(5000));
  EXPECT_FALSE(o.passed);
  EXPECT_EQ(o.window_from, std::nullopt);
  EXPECT_EQ(o.window_to, std::nullopt);
  EXPECT_EQ(o.message,
            "expected car received MV:STOP within 300 ms after step 'release', but step 'release' "
            "never happened");

  add_step_end(t, ms(2000), "release");
  const Expectation second =
      expect_in(car_received("MV:STOP"),
                Window{Anchor{step_end("release"), 2, milliseconds(100)}, milliseconds(300)});
  const auto o2 = check(second, t, ms(5000));
  EXPECT_FALSE(o2.passed);
  EXPECT_EQ(o2.message,
            "expected car received MV:STOP within 300 ms after the 2nd step 'release' + 100 ms, "
            "but the 2nd step 'release' never happened (step 'release' happened once)");
  ASSERT_EQ(o2.evidence.size(), 1u);
  EXPECT_EQ(o2.evidence[0].at, ms(2000));
}

TEST(ExpectWindow, AnOffsetAnchorMovesTheWindow) {
  Expectation e =
      expect_in(car_received("MV:STOP"),
                Window{Anchor{step_end("release"), 1, milliseconds(200)}, milliseconds(200)});
  const auto o = check(e, release_then_stop(ms(1400)), ms(5000));
  EXPECT_TRUE(o.passed) << o.message;
  EXPECT_EQ(o.window_from, ms(1200));
  EXPECT_EQ(o.window_to, ms(1400));
  EXPECT_EQ(o.label, "car received MV:STOP within 200 ms after step 'release' + 200 ms");
}

}  // namespace
}  // namespace hil::harness
