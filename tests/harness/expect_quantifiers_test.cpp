// What each quantifier of the expectation checker accepts on timelines built
// by hand, what a failure tells the QA engineer who reads it, the release
// checks of docs/scenarios.md, and the slack of a real-time run.

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "harness/expect.hpp"
#include "tests/harness/expect_support.hpp"

namespace hil::harness {
namespace {

using namespace test;

// -------------------------------------------------------------- quantifiers

class ExpectCounting : public ::testing::Test {
 protected:
  void SetUp() override {
    add_delivered(t_, ms(500), "ST:RUN");
    add_delivered(t_, ms(1000), "MV:FWD");
    add_delivered(t_, ms(2000), "MV:FWD");
    add_delivered(t_, ms(3000), "MV:FWD");
    add_delivered(t_, ms(9000), "MV:FWD");
  }
  ExpectationOutcome run(Quantifier q, std::uint64_t count = 0) {
    return check(expect_in(car_received("MV:FWD"), between(ms(1000), seconds(4)), q, count), t_,
                 ms(10000));
  }
  /// run(q, count), expected to fail with `message`; the outcome, for more checks.
  ExpectationOutcome failing(Quantifier q, std::uint64_t count, const std::string& message) {
    auto o = run(q, count);
    EXPECT_FALSE(o.passed);
    EXPECT_EQ(o.message, message);
    return o;
  }
  Timeline t_;
};

TEST_F(ExpectCounting, ExistsNeedsOneMatchAndPointsAtTheNearestOtherwise) {
  const auto ok = run(Quantifier::exists);
  EXPECT_TRUE(ok.passed);
  EXPECT_EQ(ok.label, "car received MV:FWD between 1 s and 5 s");
  EXPECT_EQ(ok.line, 7);
  EXPECT_EQ(ok.message,
            "expected at least one 'car received MV:FWD' between 1.000 s and 5.000 s, found 3: at "
            "1.000 s, 2.000 s, 3.000 s");

  const auto missing =
      check(expect_in(car_received("MV:FWD"), between(ms(4000), milliseconds(500))), t_, ms(10000));
  EXPECT_FALSE(missing.passed);
  EXPECT_EQ(missing.message,
            "expected at least one 'car received MV:FWD' between 4.000 s and 4.500 s, found none; "
            "the nearest at 3.000 s, 1.000 s early");

  const auto nowhere = check(
      expect_in(car_received("MV:STOP"), between(ms(4000), milliseconds(500))), t_, ms(10000));
  EXPECT_EQ(nowhere.message,
            "expected at least one 'car received MV:STOP' between 4.000 s and 4.500 s, found none "
            "in the whole run");
}

TEST_F(ExpectCounting, NeverFailsOnAnyMatchAndListsThem) {
  const auto o = run(Quantifier::never);
  EXPECT_FALSE(o.passed);
  EXPECT_EQ(o.label, "car received MV:FWD between 1 s and 5 s, never");
  EXPECT_EQ(o.message,
            "expected no 'car received MV:FWD' between 1.000 s and 5.000 s, found 3: at 1.000 s, "
            "2.000 s, 3.000 s");
  const auto quiet =
      check(expect_in(car_received("MV:FWD"), between(ms(4000), seconds(4)), Quantifier::never), t_,
            ms(10000));
  EXPECT_TRUE(quiet.passed);
  EXPECT_EQ(quiet.message,
            "expected no 'car received MV:FWD' between 4.000 s and 8.000 s, found none");
}

TEST_F(ExpectCounting, ExactlyWantsTheCountNotMoreNotLess) {
  EXPECT_TRUE(run(Quantifier::exactly, 3).passed);
  const auto more = failing(Quantifier::exactly, 2,
                            "expected exactly 2 'car received MV:FWD' between 1.000 s and 5.000 s, "
                            "found 3: at 1.000 s, 2.000 s, 3.000 s");
  EXPECT_EQ(more.label, "car received MV:FWD between 1 s and 5 s, exactly twice");
  failing(Quantifier::exactly, 4,
          "expected exactly 4 'car received MV:FWD' between 1.000 s and 5.000 s, found 3: at "
          "1.000 s, 2.000 s, 3.000 s; the nearest outside the window at 9.000 s, 4.000 s late");
}

TEST_F(ExpectCounting, AtLeastAndAtMostBoundTheCountInclusively) {
  EXPECT_TRUE(run(Quantifier::at_least, 3).passed);
  EXPECT_TRUE(run(Quantifier::at_least, 0).passed);
  const auto few = failing(Quantifier::at_least, 4,
                           "expected at least 4 'car received MV:FWD' between 1.000 s and 5.000 s, "
                           "found 3: at 1.000 s, 2.000 s, 3.000 s; the nearest outside the window "
                           "at 9.000 s, 4.000 s late");
  EXPECT_EQ(few.label, "car received MV:FWD between 1 s and 5 s, at least 4 times");

  EXPECT_TRUE(run(Quantifier::at_most, 3).passed);
  failing(Quantifier::at_most, 2,
          "expected at most 2 'car received MV:FWD' between 1.000 s and 5.000 s, found 3: at "
          "1.000 s, 2.000 s, 3.000 s");
}

TEST(ExpectCountingLists, OnlyTheFirstFewTimesAreListed) {
  Timeline t;
  for (int i = 1; i <= 8; ++i)
    add_delivered(t, ms(100 * i), "MV:FWD");
  const auto o =
      check(expect_in(car_received("MV:FWD"), whole_run(), Quantifier::at_most, 5), t, ms(1000));
  EXPECT_FALSE(o.passed);
  EXPECT_EQ(o.message,
            "expected at most 5 'car received MV:FWD' between 0.000 s and 1.000 s, found 8: at "
            "0.100 s, 0.200 s, 0.300 s, 0.400 s, 0.500 s and 3 more");
}

class ExpectAtTimes : public ::testing::Test {
 protected:
  void SetUp() override {
    t_.add(ms(5000), WireKind::close, {{"by", "fault"}, {"reason", "dropped"}});
    t_.add(ms(6100), ClientKind::connection, {{"state", "connected"}});
    t_.add(ms(7900), ClientKind::connection, {{"state", "connected"}});
    t_.add(ms(9500), ClientKind::connection, {{"state", "connected"}});
    t_.add(ms(11250), ClientKind::connection, {{"state", "connected"}});
  }
  Expectation at(std::vector<Duration> times, bool only = false) {
    Expectation e = expect_in(client_state("connected"), whole_run(), Quantifier::at_times);
    e.times = std::move(times);
    e.tolerance = milliseconds(250);
    e.only = only;
    return e;
  }
  Timeline t_;
};

TEST_F(ExpectAtTimes, NeedsAMatchNearEachTimeWithBothTolerancesIncluded) {
  expect_passed(check(at({seconds(6), seconds(8), seconds(11)}), t_, ms(20000)),
                "client connected, at 6 s, 8 s, 11 s ± 250 ms",
                "expected 'client connected' at 6.000 s, 8.000 s, 11.000 s (± 0.250 s) between "
                "0.000 s and 20.000 s, found at 6.100 s, 7.900 s, 11.250 s");
}

TEST_F(ExpectAtTimes, SaysWhichTimeHadNoMatchAndWhereTheNearestWas) {
  const auto o = check(at({seconds(6), seconds(8), seconds(10)}), t_, ms(20000));
  EXPECT_FALSE(o.passed);
  EXPECT_EQ(o.message,
            "expected 'client connected' at 6.000 s, 8.000 s, 10.000 s (± 0.250 s) between 0.000 "
            "s and 20.000 s, found at 6.100 s, 7.900 s; nothing at 10.000 s, the nearest at "
            "9.500 s, 0.500 s early");
}

TEST_F(ExpectAtTimes, UsesEachMatchOnlyOnce) {
  // 6.1 s is near both 6.0 s and 6.2 s; one connection cannot serve both.
  const auto o = check(at({seconds(6), milliseconds(6200)}), t_, ms(20000));
  EXPECT_FALSE(o.passed);
  EXPECT_EQ(o.message,
            "expected 'client connected' at 6.000 s, 6.200 s (± 0.250 s) between 0.000 s and "
            "20.000 s, found at 6.100 s; nothing at 6.200 s, the nearest at 7.900 s, 1.700 s "
            "late");
}

TEST_F(ExpectAtTimes, WithOnlyAMatchOutsideTheTimesFails) {
  EXPECT_TRUE(
      check(at({seconds(6), seconds(8), milliseconds(9500), seconds(11)}, true), t_, ms(20000))
          .passed);
  const auto o = check(at({seconds(6), seconds(8), seconds(11)}, true), t_, ms(20000));
  EXPECT_FALSE(o.passed);
  EXPECT_EQ(o.label, "client connected, only at 6 s, 8 s, 11 s ± 250 ms");
  EXPECT_EQ(o.message,
            "expected 'client connected' only at 6.000 s, 8.000 s, 11.000 s (± 0.250 s) between "
            "0.000 s and 20.000 s, found at 6.100 s, 7.900 s, 11.250 s; 1 more outside those "
            "times: at 9.500 s");
}

TEST_F(ExpectAtTimes, TimesCountFromTheWindowStart) {
  Expectation e = at({seconds(1), seconds(3), seconds(6)});
  e.window = Window{Anchor{Matcher{Source::wire, WireKind::close, {}, "link closed"}, 1, {}}, {}};
  const auto o = check(e, t_, ms(20000));
  EXPECT_TRUE(o.passed) << o.message;
  EXPECT_EQ(o.window_from, ms(5000));
  EXPECT_EQ(o.message,
            "expected 'client connected' at 6.000 s, 8.000 s, 11.000 s (± 0.250 s) between 5.000 "
            "s and 20.000 s (after link closed), found at 6.100 s, 7.900 s, 11.250 s");
}

class ExpectAlways : public ::testing::Test {
 protected:
  void SetUp() override {
    for (int i = 0; i < 10; ++i)
      t_.add(ms(1000 + 100 * i), SimKind::sample, {{"speed_mps", i < 6 ? 0.3 : 0.0}});
    t_.add(ms(1650), SimKind::at_rest);
  }
  ExpectationOutcome slow_between(Time from, Duration within) {
    return check(expect_in(Matcher{Source::sim,
                                   SimKind::sample,
                                   {test_of("speed_mps", Op::less, 0.01)},
                                   "speed below 0.01 m/s"},
                           between(from, within), Quantifier::always),
                 t_, ms(5000));
  }
  Timeline t_;
};

TEST_F(ExpectAlways, HoldsWhenEveryRecordOfTheKindPasses) {
  expect_passed(slow_between(ms(1600), milliseconds(300)),
                "speed below 0.01 m/s between 1.6 s and 1.9 s, always",
                "expected every sim sample between 1.600 s and 1.900 s to satisfy 'speed below "
                "0.01 m/s', and all 4 did");
}

TEST_F(ExpectAlways, FailsNamingTheRecordsThatDidNotAndWhatTheyHad) {
  const auto o = slow_between(ms(1000), milliseconds(900));
  EXPECT_FALSE(o.passed);
  EXPECT_EQ(o.message,
            "expected every sim sample between 1.000 s and 1.900 s to satisfy 'speed below 0.01 "
            "m/s'; 6 of 10 did not: at 1.000 s, 1.100 s, 1.200 s, 1.300 s, 1.400 s and 1 more "
            "(the first had speed_mps = 0.3)");
}

TEST_F(ExpectAlways, FailsWhenThereIsNothingToJudge) {
  const auto o = slow_between(ms(3000), seconds(1));
  EXPECT_FALSE(o.passed);
  EXPECT_EQ(o.message,
            "expected every sim sample between 3.000 s and 4.000 s to satisfy 'speed below 0.01 "
            "m/s', but there was no record to judge");
}

// ------------------------------------------------------- labels and evidence

TEST(ExpectLabel, TheScenariosOwnLabelWinsAndOneIsMadeOtherwise) {
  Timeline t;
  Expectation e = stop_within_300ms_of_release();
  EXPECT_EQ(check(e, t, ms(1000)).label, "car received MV:STOP within 300 ms after step 'release'");
  e.label = "the car stops when the button is released";
  EXPECT_EQ(check(e, t, ms(1000)).label, "the car stops when the button is released");

  // A matcher without the scenario's text is described from its fields.
  const Expectation bare =
      expect_in(Matcher{Source::wire, WireKind::frame, {test_of("valid", Op::equals, false)}, ""},
                whole_run(), Quantifier::never);
  EXPECT_EQ(check(bare, t, ms(1000)).label, "wire frame where valid = false, never");
  const Expectation last =
      expect_in(car_received("MV:STOP"), Window{Anchor{step_end("release"), -1, {}}, {}},
                Quantifier::at_most, 1);
  EXPECT_EQ(check(last, t, ms(1000)).label,
            "car received MV:STOP after the last step 'release', at most once");
}

TEST(ExpectEvidence, TheMatchesAndTheSameSourceAroundTheEdgesInTimeOrder) {
  Timeline t;
  t.add(ms(400), WireKind::frame, frame_data("to_client", "delivered", "FB:ST"));  // too early
  t.add(ms(600), WireKind::frame, frame_data("to_client", "delivered", "FB:ST"));
  add_step_end(t, ms(1000), "release");  // another source
  add_delivered(t, ms(1200), "MV:STOP");
  t.add(ms(1800), WireKind::frame, frame_data("to_client", "delivered", "FB:ST"));
  t.add(ms(2000), WireKind::frame, frame_data("to_client", "delivered", "FB:ST"));  // far
  add_delivered(t, ms(2500), "MV:STOP");
  t.add(ms(2700), WireKind::frame, frame_data("to_client", "delivered", "FB:ST"));
  const auto o =
      check(expect_in(car_received("MV:STOP"), between(ms(1000), milliseconds(300))), t, ms(4000));
  EXPECT_TRUE(o.passed);
  EXPECT_EQ(times_of(o.evidence), (std::vector<Time>{ms(600), ms(1200), ms(1800)}));

  // A miss shows the nearest match too.
  const auto miss =
      check(expect_in(car_received("MV:STOP"), between(ms(2000), milliseconds(300))), t, ms(4000));
  EXPECT_FALSE(miss.passed);
  EXPECT_EQ(times_of(miss.evidence), (std::vector<Time>{ms(1800), ms(2000), ms(2500), ms(2700)}));
}

TEST(ExpectEvidence, KeepsAtMostTenMatchesAndTwentyRecords) {
  Timeline t;
  for (int i = 0; i < 30; ++i)
    t.add(ms(700 + 10 * i), WireKind::frame, frame_data("to_client", "delivered", "FB:ST"));
  for (int i = 0; i < 30; ++i)
    add_delivered(t, ms(1000 + 10 * i), "MV:FWD");
  const auto o = check(
      expect_in(car_received("MV:FWD"), between(ms(1000), seconds(1)), Quantifier::at_least, 1), t,
      ms(5000));
  ASSERT_EQ(o.evidence.size(), 20u);
  EXPECT_TRUE(std::is_sorted(o.evidence.begin(), o.evidence.end(),
                             [](const Record& a, const Record& b) { return a.at < b.at; }));
  const auto matched = std::count_if(o.evidence.begin(), o.evidence.end(),
                                     [](const Record& r) { return r.data["frame"] == "MV:FWD"; });
  EXPECT_EQ(matched, 10);
}

TEST(ExpectCheckAll, ChecksEachInOrder) {
  Timeline t;
  add_delivered(t, ms(100), "ST:RUN");
  Expectation first = expect_in(car_received("ST:RUN"), whole_run());
  first.line = 3;
  Expectation second = expect_in(car_received("ST:RUN"), whole_run(), Quantifier::never);
  second.line = 4;
  const auto outcomes = check_all({first, second}, t, ms(1000));
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_EQ(outcomes[0].line, 3);
  EXPECT_TRUE(outcomes[0].passed);
  EXPECT_EQ(outcomes[1].line, 4);
  EXPECT_FALSE(outcomes[1].passed);
}

// ------------------------------------------ the six release checks of docs/scenarios.md

// "the car received MV:STOP within 300 ms of the release"
TEST(ExpectIssueExamples, StopWithin300msOfTheRelease) {
  const Expectation e = stop_within_300ms_of_release();
  // The release at 5 s, MV:STOP sent at 5.05 s and received at `received`.
  const auto timeline = [](Time received) {
    Timeline t;
    add_step_end(t, ms(5000), "release");
    t.add(ms(5050), WireKind::frame, frame_data("to_car", "sent", "MV:STOP"));
    add_delivered(t, received, "MV:STOP");
    return t;
  };
  const auto ok = check(e, timeline(ms(5080)), ms(6000));
  EXPECT_TRUE(ok.passed);
  EXPECT_EQ(ok.message,
            "expected at least one 'car received MV:STOP' between 5.000 s and 5.300 s (within 300 "
            "ms after step 'release'), found 1: at 5.080 s");

  const auto late = check(e, timeline(ms(5812)), ms(6000));
  EXPECT_FALSE(late.passed);
  EXPECT_EQ(late.message,
            "expected at least one 'car received MV:STOP' between 5.000 s and 5.300 s (within 300 "
            "ms after step 'release'), found none; the nearest at 5.812 s, 0.512 s late");
  EXPECT_EQ(times_of(late.evidence), (std::vector<Time>{ms(5050), ms(5812)}));
}

// "after the connection dropped at 5 s the client reconnected at 6 s, 8 s and
// 11 s, each within 250 ms"
TEST(ExpectIssueExamples, ReconnectsOnTheBackoffSchedule) {
  Expectation e = expect_in(
      client_state("connected"),
      Window{Anchor{Matcher{Source::wire, WireKind::close, {}, "link closed"}, 1, {}}, {}},
      Quantifier::at_times);
  e.times = {seconds(1), seconds(3), seconds(6)};
  e.tolerance = milliseconds(250);
  const auto timeline = [](std::vector<std::int64_t> reconnects_ms) {
    Timeline t;
    t.add(ms(200), ClientKind::connection, {{"state", "connected"}});
    t.add(ms(5000), WireKind::close, {{"by", "fault"}, {"reason", "dropped"}});
    for (const auto at : reconnects_ms) {
      t.add(ms(at - 1), ClientKind::connection, {{"state", "connecting"}});
      t.add(ms(at), ClientKind::connection, {{"state", "connected"}});
    }
    return t;
  };
  const auto ok = check(e, timeline({6000, 8100, 10800}), ms(15000));
  EXPECT_TRUE(ok.passed) << ok.message;
  const auto eager = check(e, timeline({5100, 5200, 5300}), ms(15000));
  EXPECT_FALSE(eager.passed);
  EXPECT_EQ(eager.message,
            "expected 'client connected' at 6.000 s, 8.000 s, 11.000 s (± 0.250 s) between 5.000 "
            "s and 15.000 s (after link closed), found none of them; nothing at 6.000 s, the "
            "nearest at 5.300 s, 0.700 s early; nothing at 8.000 s, the nearest at 5.300 s, 2.700 "
            "s early; nothing at 11.000 s, the nearest at 5.300 s, 5.700 s early");
}

// "exactly one ST:RUN was received"
TEST(ExpectIssueExamples, ExactlyOneRun) {
  const Expectation e = expect_in(car_received("ST:RUN"), whole_run(), Quantifier::exactly, 1);
  Timeline t;
  add_delivered(t, ms(1000), "ST:RUN");
  t.add(ms(1000), WireKind::frame, frame_data("to_car", "sent", "ST:RUN"));
  EXPECT_TRUE(check(e, t, ms(3000)).passed);
  add_delivered(t, ms(2000), "ST:RUN");
  const auto twice = check(e, t, ms(3000));
  EXPECT_FALSE(twice.passed);
  EXPECT_EQ(twice.label, "car received ST:RUN, exactly once");
  EXPECT_EQ(twice.message,
            "expected exactly 1 'car received ST:RUN' between 0.000 s and 3.000 s, found 2: at "
            "1.000 s, 2.000 s");
}

// "the car reached station 002 within 90 s and stopped"
TEST(ExpectIssueExamples, ReachesStationTwoAndStops) {
  const Matcher station{
      Source::sim, SimKind::station, {test_of("station", Op::equals, 2)}, "station 2"};
  const Expectation reached = expect_in(station, between(ms(0), seconds(90)));
  const Expectation stopped =
      expect_in(Matcher{Source::sim, SimKind::at_rest, {}, "chassis at rest"},
                Window{Anchor{station, 1, {}}, seconds(1)});
  // Station 1 at 30 s, station 2 at `station_2`, at rest at `at_rest`.
  const auto timeline = [](Time station_2, Time at_rest) {
    Timeline t;
    t.add(ms(30000), SimKind::station, {{"station", 1}});
    t.add(station_2, SimKind::station, {{"station", 2}});
    t.add(at_rest, SimKind::at_rest);
    return t;
  };
  const auto both = check_all({reached, stopped}, timeline(ms(61000), ms(61400)), ms(62000));
  EXPECT_TRUE(both[0].passed);
  EXPECT_TRUE(both[1].passed) << both[1].message;

  const auto failed = check_all({reached, stopped}, timeline(ms(91000), ms(93000)), ms(95000));
  EXPECT_FALSE(failed[0].passed);
  EXPECT_EQ(failed[0].message,
            "expected at least one 'station 2' between 0.000 s and 90.000 s, found none; the "
            "nearest at 91.000 s, 1.000 s late");
  EXPECT_FALSE(failed[1].passed);
  EXPECT_EQ(failed[1].message,
            "expected at least one 'chassis at rest' between 91.000 s and 92.000 s (within 1 s "
            "after station 2), found none; the nearest at 93.000 s, 1.000 s late");
}

// "the client never sent a frame with a bad checksum"
TEST(ExpectIssueExamples, NeverABadChecksumFromTheClient) {
  const Expectation e =
      expect_in(Matcher{Source::wire,
                        WireKind::frame,
                        {test_of("dir", Op::equals, "to_car"), test_of("stage", Op::equals, "sent"),
                         test_of("error", Op::equals, "checksum")},
                        "client sent a frame with a bad checksum"},
                whole_run(), Quantifier::never);
  Timeline t;
  t.add(ms(1000), WireKind::frame, frame_data("to_car", "sent", "MV:FWD"));
  // Corrupted on the way by a fault: the client is not to blame.
  t.add(ms(1000), WireKind::frame,
        {{"dir", "to_car"}, {"stage", "delivered"}, {"valid", false}, {"error", "checksum"}});
  const auto ok = check(e, t, ms(5000));
  EXPECT_TRUE(ok.passed) << ok.message;

  t.add(ms(2500), WireKind::frame,
        {{"dir", "to_car"}, {"stage", "sent"}, {"valid", false}, {"error", "checksum"}});
  const auto bad = check(e, t, ms(5000));
  EXPECT_FALSE(bad.passed);
  EXPECT_EQ(bad.message,
            "expected no 'client sent a frame with a bad checksum' between 0.000 s and 5.000 s, "
            "found 1: at 2.500 s");
  ASSERT_FALSE(bad.evidence.empty());
  EXPECT_EQ(bad.evidence.back().at, ms(2500));
}

// "the chassis was at rest within 1 s of the emergency stop"
TEST(ExpectIssueExamples, AtRestWithinOneSecondOfTheEmergencyStop) {
  const Expectation e = expect_in(Matcher{Source::sim, SimKind::at_rest, {}, "chassis at rest"},
                                  Window{Anchor{step_end("estop"), 1, {}}, seconds(1)});
  // At rest at 1 s, moving at 2 s, the emergency stop at 4 s, and then...
  Timeline coasting;
  coasting.add(ms(1000), SimKind::at_rest);
  coasting.add(ms(2000), SimKind::moving);
  add_step_end(coasting, ms(4000), "estop");
  // ... at rest again at 4.6 s.
  Timeline good = coasting;
  good.add(ms(4600), SimKind::at_rest);
  EXPECT_TRUE(check(e, good, ms(6000)).passed);

  // ... still moving.
  const auto o = check(e, coasting, ms(6000));
  EXPECT_FALSE(o.passed);
  EXPECT_EQ(o.message,
            "expected at least one 'chassis at rest' between 4.000 s and 5.000 s (within 1 s "
            "after step 'estop'), found none; the nearest at 1.000 s, 3.000 s early");
}

// --------------------------------------------------------------- properties

struct RandomRun {
  Timeline timeline;
  Time from{0};
  Duration within{0};
};

// Records of two sources at random whole milliseconds, some of them the
// frame the expectations look for.
RandomRun random_run() {
  RandomRun run;
  auto ats = *rc::gen::container<std::vector<int>>(rc::gen::inRange(0, 2000));
  std::sort(ats.begin(), ats.end());
  for (const int at : ats) {
    const int pick = *rc::gen::inRange(0, 3);
    if (pick == 0)
      add_delivered(run.timeline, ms(at), "MV:STOP");
    else if (pick == 1)
      add_delivered(run.timeline, ms(at), "MV:FWD");
    else
      run.timeline.add(ms(at), ClientKind::connection, {{"state", "connected"}});
  }
  run.from = ms(*rc::gen::inRange(0, 2000));
  run.within = milliseconds(*rc::gen::inRange(0, 1000));
  return run;
}

RC_GTEST_PROP(ExpectProperties, CountingQuantifiersAgreeWithABruteForceCount, ()) {
  const RandomRun run = random_run();
  const Matcher what = car_received("MV:STOP");
  std::uint64_t brute = 0;
  for (const auto& r : run.timeline.records())
    if (r.source() == Source::wire && r.data["frame"] == "MV:STOP" && r.at >= run.from &&
        r.at <= run.from + run.within)
      ++brute;
  const auto count = static_cast<std::uint64_t>(*rc::gen::inRange(0, 6));
  const auto passes = [&](Quantifier q) {
    return check(expect_in(what, between(run.from, run.within), q, count), run.timeline, ms(3000))
        .passed;
  };
  RC_ASSERT(passes(Quantifier::exists) == (brute >= 1));
  RC_ASSERT(passes(Quantifier::never) == (brute == 0));
  RC_ASSERT(passes(Quantifier::exactly) == (brute == count));
  RC_ASSERT(passes(Quantifier::at_least) == (brute >= count));
  RC_ASSERT(passes(Quantifier::at_most) == (brute <= count));
}

RC_GTEST_PROP(ExpectProperties, AWiderWindowFindsAtLeastAsMuch, ()) {
  const RandomRun run = random_run();
  const Duration wider = run.within + milliseconds(*rc::gen::inRange(0, 1000));
  const Matcher what = car_received("MV:STOP");
  const auto outcome = [&](Duration within, Quantifier q) {
    return check(expect_in(what, between(run.from, within), q), run.timeline, ms(3000));
  };
  if (outcome(run.within, Quantifier::exists).passed)
    RC_ASSERT(outcome(wider, Quantifier::exists).passed);
  if (outcome(wider, Quantifier::never).passed)
    RC_ASSERT(outcome(run.within, Quantifier::never).passed);
  RC_ASSERT(*outcome(wider, Quantifier::exists).window_to >=
            *outcome(run.within, Quantifier::exists).window_to);
}

RC_GTEST_PROP(ExpectProperties, MatchesAtTheAskedTimesAlwaysSatisfyAtTimes, ()) {
  auto offsets = *rc::gen::container<std::vector<int>>(rc::gen::inRange(0, 5000));
  std::sort(offsets.begin(), offsets.end());
  const int jitter_ms = *rc::gen::inRange(-250, 251);
  Timeline t;
  Expectation e = expect_in(client_state("connected"), whole_run(), Quantifier::at_times);
  e.tolerance = milliseconds(250);
  e.only = true;
  for (const int at : offsets) {
    t.add(ms(at + 300 + jitter_ms), ClientKind::connection, {{"state", "connected"}});
    e.times.push_back(ms(at + 300));
  }
  const auto o = check(e, t, ms(6000));
  RC_ASSERT(o.passed);
}

// ------------------------------------------------------- real-time slack

Window run_times(std::int64_t from_ms, std::int64_t to_ms) {
  return Window{Anchor{std::nullopt, 1, milliseconds(from_ms)}, milliseconds(to_ms - from_ms)};
}

TEST(ExpectSlack, WhatMustHappenMayFallInTheWidenedWindow) {
  Timeline t;
  add_delivered(t, ms(5050), "MV:STOP");
  const auto e = expect_in(car_received("MV:STOP"), run_times(5000, 5001));
  EXPECT_FALSE(check(e, t, ms(10000)).passed);
  EXPECT_FALSE(check(e, t, ms(10000), milliseconds(40)).passed) << "50 ms late is past 40 ms";
  const auto o = check(e, t, ms(10000), milliseconds(100));
  EXPECT_TRUE(o.passed) << o.message;
  EXPECT_NE(o.message.find("(± 0.100 s for real time)"), std::string::npos) << o.message;
}

TEST(ExpectSlack, WhatMustNotHappenIsLookedForInTheNarrowedWindow) {
  Timeline t;
  add_delivered(t, ms(2050), "MV:FWD");
  add_delivered(t, ms(3950), "MV:FWD");
  const auto e = expect_in(car_received("MV:FWD"), run_times(2000, 4000), Quantifier::never);
  EXPECT_FALSE(check(e, t, ms(10000)).passed);
  EXPECT_TRUE(check(e, t, ms(10000), milliseconds(100)).passed);
  add_delivered(t, ms(3000), "MV:FWD");
  const auto o = check(e, t, ms(10000), milliseconds(100));
  EXPECT_FALSE(o.passed) << "well inside the window it still counts";
  EXPECT_NE(o.message.find("found 1: at 3.000 s"), std::string::npos) << o.message;
}

TEST(ExpectSlack, ExactlyTakesItsLowerBoundWideAndItsUpperBoundNarrow) {
  // A STAT every 500 ms; the window ends just before the one at 12 s.
  Timeline t;
  for (int i = 1; i <= 24; ++i)
    add_delivered(t, ms(500 * i), "STAT");
  const auto e = expect_in(car_received("STAT"), run_times(0, 11999), Quantifier::exactly, 23);
  EXPECT_TRUE(check(e, t, ms(13000)).passed);
  EXPECT_TRUE(check(e, t, ms(13000), milliseconds(100)).passed)
      << "the one at 12.0 s lies in the slack only";
  const auto too_few =
      expect_in(car_received("STAT"), run_times(0, 11999), Quantifier::exactly, 25);
  EXPECT_FALSE(check(too_few, t, ms(13000), milliseconds(100)).passed);
  const auto too_many =
      expect_in(car_received("STAT"), run_times(0, 11999), Quantifier::exactly, 21);
  EXPECT_FALSE(check(too_many, t, ms(13000), milliseconds(100)).passed)
      << "22 are well inside: more than 21 whatever the edges";
}

TEST(ExpectSlack, AnEventEdgeDoesNotMove) {
  Timeline t;
  add_delivered(t, ms(990), "MV:STOP");  // before the release: not caused by it
  add_step_end(t, ms(1000), "release");
  Window after_release{Anchor{step_end("release"), 1, Duration(0)}, milliseconds(300)};
  const auto e = expect_in(car_received("MV:STOP"), after_release);
  EXPECT_FALSE(check(e, t, ms(5000), milliseconds(100)).passed);
  add_delivered(t, ms(1350), "MV:STOP");  // 50 ms past the window's end
  EXPECT_TRUE(check(e, t, ms(5000), milliseconds(100)).passed);
}

TEST(ExpectSlack, TimesGetTheSlackOnTheirTolerance) {
  Timeline t;
  t.add(ms(6080), ClientKind::connection, {{"state", "connecting"}});
  Expectation e =
      expect_in(client_state("connecting"), run_times(5000, 20000), Quantifier::at_times);
  e.times = {seconds(1)};
  e.tolerance = milliseconds(1);
  EXPECT_FALSE(check(e, t, ms(20000)).passed);
  EXPECT_TRUE(check(e, t, ms(20000), milliseconds(100)).passed);
}

}  // namespace
}  // namespace hil::harness
