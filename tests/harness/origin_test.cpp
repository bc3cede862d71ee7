// The origin of a run with an external program, in virtual time with exact
// times: where OriginWatch fixes it (the first connection, the first result
// line, or the program's start when neither comes in time), and how the
// scenario's run times count from it when the run is judged.

#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "harness/judging.hpp"
#include "harness/origin.hpp"
#include "link/executor.hpp"
#include "tests/harness/expect_support.hpp"

namespace hil::harness {
namespace {

using namespace test;

/// A watch made at `program_start` on a virtual clock, and what it told.
class OriginWatchTest : public ::testing::Test {
 protected:
  void start_program_at(Time program_start, Duration startup_timeout = seconds(10)) {
    executor_.run_until(program_start);
    watch_.emplace(executor_, timeline_, startup_timeout);
    watch_->when_fixed([this](const Origin& o) { told_.push_back({executor_.now(), o}); });
  }
  void at(Time t, RecordKind kind, nlohmann::json data = nlohmann::json::object()) {
    executor_.run_until(t);
    timeline_.add(kind, std::move(data));
  }
  std::vector<Record> origin_records() const {
    std::vector<Record> out;
    for (const auto& r : timeline_.timeline().records())
      if (r.kind == ClientKind::origin) out.push_back(r);
    return out;
  }

  struct Told {
    Time when{0};
    Origin origin;
  };
  link::VirtualExecutor executor_;
  RunTimeline timeline_{executor_};
  std::optional<OriginWatch> watch_;
  std::vector<Told> told_;
};

TEST_F(OriginWatchTest, TheFirstConnectionFixesItAtItsExactTimeAndTheTimelineSaysWhere) {
  start_program_at(ms(0));
  at(ms(300), ClientKind::output, {{"line", "starting the JVM"}});
  at(ms(612), WireKind::open, {{"client", "c"}, {"car", "car0"}});
  at(ms(900), WireKind::open, {{"client", "c"}, {"car", "car0"}});
  executor_.run_until(seconds(20));
  ASSERT_EQ(told_.size(), 1u) << "told once";
  EXPECT_EQ(told_[0].when, ms(612));
  EXPECT_EQ(told_[0].origin, (Origin{ms(612), Origin::Cause::first_connection}));
  EXPECT_EQ(watch_->settled(), (Origin{ms(612), Origin::Cause::first_connection}));
  const auto records = origin_records();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].at, ms(612));
  EXPECT_EQ(records[0].data["cause"], "connection");
  EXPECT_EQ(records[0].data["text"], "origin: the client's first connection at +0.612 s");
}

TEST_F(OriginWatchTest, ASerialCarsFirstByteCountsButTheCarsOwnBytesDoNot) {
  start_program_at(ms(0));
  at(ms(100), WireKind::frame, frame_data("to_client", "sent", "PONG"));
  EXPECT_FALSE(watch_->origin());
  at(ms(450), WireKind::frame, frame_data("to_car", "sent", "PING"));
  EXPECT_EQ(watch_->origin(), (Origin{ms(450), Origin::Cause::first_connection}));
}

TEST_F(OriginWatchTest, AConnectionRefusedByAFaultIsTheFirstContact) {
  // A car that refuses connections at first: the refused attempt is the
  // program reaching the car, so a `refuse` counted from the origin
  // (at: 0s, for: 1.5s) refuses it and the retries after it.
  start_program_at(ms(0));
  at(ms(200), link::FaultKind::refuse, {{"dir", "to_car"}, {"rule", "r"}, {"detail", ""}});
  EXPECT_EQ(watch_->origin(), (Origin{ms(200), Origin::Cause::first_connection}));
  executor_.run_until(ms(1700));
  watch_->first_result();
  EXPECT_EQ(watch_->settled(), (Origin{ms(200), Origin::Cause::first_connection}));
  ASSERT_EQ(told_.size(), 1u);
  EXPECT_EQ(told_[0].when, ms(200));
}

TEST_F(OriginWatchTest, AResultLineBeforeAnyContactFixesItThere) {
  // A program that answers its first action before it ever reached the
  // car (an action it refuses itself, say).
  start_program_at(ms(0));
  at(ms(100), WireKind::frame, frame_data("to_client", "sent", "STAT"));
  executor_.run_until(ms(1700));
  watch_->first_result();
  at(ms(2500), WireKind::open);
  EXPECT_EQ(watch_->settled(), (Origin{ms(1700), Origin::Cause::first_result}));
  ASSERT_EQ(told_.size(), 1u);
  EXPECT_EQ(told_[0].when, ms(1700));
}

TEST_F(OriginWatchTest, NeitherWithinTheStartupTimeoutMeansTheProgramsStart) {
  start_program_at(ms(50), seconds(3));
  executor_.run_until(ms(3049));
  EXPECT_TRUE(told_.empty());
  executor_.run_until(ms(3050));
  ASSERT_EQ(told_.size(), 1u);
  EXPECT_EQ(told_[0].when, ms(3050)) << "known once the startup timeout is over";
  EXPECT_EQ(told_[0].origin, (Origin{ms(50), Origin::Cause::program_start}));
  at(ms(4000), WireKind::open);
  EXPECT_EQ(watch_->settled().cause, Origin::Cause::program_start) << "a late connection is late";
  const auto records = origin_records();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].data["text"], "origin: the client program's start at +0.050 s");
}

TEST_F(OriginWatchTest, ARunThatEndsBeforeAnySignSettlesOnTheProgramsStart) {
  start_program_at(ms(20));
  executor_.run_until(ms(900));
  EXPECT_EQ(watch_->settled(), (Origin{ms(20), Origin::Cause::program_start}));
  EXPECT_EQ(told_.size(), 1u);
}

TEST_F(OriginWatchTest, ACallbackAddedOnceFixedRunsAtOnce) {
  start_program_at(ms(0));
  at(ms(250), WireKind::open);
  std::optional<Time> got;
  watch_->when_fixed([&](const Origin& o) { got = o.at; });
  EXPECT_EQ(got, ms(250));
}

TEST(OriginFaults, TimedRulesAndWindowsMoveWithTheOriginAndFrameRulesStay) {
  link::FaultProfile profile;
  link::FaultRule reset;
  reset.trigger.at = ms(2000);
  reset.action = link::Reset{};
  link::FaultRule drop_for_a_while;
  drop_for_a_while.window = link::TimeWindow{ms(1000), ms(3000)};
  drop_for_a_while.trigger.match = "SP";
  drop_for_a_while.action = link::Drop{};
  link::FaultRule drop_from_the_start;
  drop_from_the_start.window.to = ms(500);
  drop_from_the_start.action = link::Drop{};
  link::FaultRule every_frame;
  every_frame.trigger.match = "MV";
  every_frame.action = link::Drop{};
  profile.rules = {reset, drop_for_a_while, drop_from_the_start, every_frame};
  EXPECT_TRUE(has_timed_rules(profile));
  EXPECT_FALSE(has_timed_rules(link::FaultProfile{{every_frame}}));

  const auto m = moved(profile, milliseconds(612));
  EXPECT_EQ(m.rules[0].trigger.at, ms(2612));
  EXPECT_EQ(m.rules[1].window, (link::TimeWindow{ms(1612), ms(3612)}));
  EXPECT_EQ(m.rules[2].window, (link::TimeWindow{ms(0), ms(1112)})) << "still open from 0";
  EXPECT_EQ(m.rules[3], every_frame);
}

TEST(OriginFaults, UntilTheOriginWhatHoldsFromTheStartHoldsAndLaterRulesWait) {
  link::FaultProfile profile;
  link::FaultRule refuse;  // refuse connections from 0 s for 1.5 s
  refuse.trigger.at = ms(0);
  refuse.action = link::Refuse{milliseconds(1500)};
  link::FaultRule reset;  // a reset at 2 s
  reset.trigger.at = ms(2000);
  reset.action = link::Reset{};
  link::FaultRule drop_from_the_start;  // SP dropped in the first 500 ms
  drop_from_the_start.window.to = ms(500);
  drop_from_the_start.trigger.match = "SP";
  drop_from_the_start.action = link::Drop{};
  link::FaultRule drop_later;  // SP dropped from 1 s to 3 s
  drop_later.window = link::TimeWindow{ms(1000), ms(3000)};
  drop_later.trigger.match = "SP";
  drop_later.action = link::Drop{};
  link::FaultRule every_frame;
  every_frame.trigger.match = "MV";
  every_frame.action = link::Drop{};
  profile.rules = {refuse, reset, drop_from_the_start, drop_later, every_frame};

  const auto waiting = awaiting_origin(profile);
  const Time year = Time(0) + std::chrono::hours(24 * 365);
  // In force from 0: held in force, however late the program comes.
  EXPECT_EQ(waiting.rules[0].trigger.at, ms(0));
  EXPECT_EQ(std::get<link::Refuse>(waiting.rules[0].action).duration, year - Time(0));
  EXPECT_EQ(waiting.rules[2].window, (link::TimeWindow{ms(0), std::nullopt}));
  // Later: not before the origin.
  EXPECT_EQ(waiting.rules[1].trigger.at, year);
  EXPECT_EQ(waiting.rules[3].window, (link::TimeWindow{year, std::nullopt}))
      << "a valid window, however late";
  EXPECT_FALSE(link::rule_problem(waiting.rules[3]).has_value());
  EXPECT_EQ(waiting.rules[4], every_frame);
  // Once the origin is known, moved() puts the profile as written in force.
  const auto m = moved(profile, milliseconds(2013));
  EXPECT_EQ(m.rules[0].trigger.at, ms(2013));
  EXPECT_EQ(std::get<link::Refuse>(m.rules[0].action).duration, milliseconds(1500));
}

// ------------------------------------------------------- judging from it

/// A run whose program first connected at 612 ms.
const Origin kConnectedAt612{ms(612), Origin::Cause::first_connection};

/// The verdict on `e` over `t` from the origin, the session ending at 20 s.
ExpectationOutcome judged(const Expectation& e, const Timeline& t,
                          const Origin& origin = kConnectedAt612) {
  return check(e, t, seconds(20), Duration(0), origin);
}

TEST(OriginJudging, AnAtEdgeCountsFromTheOriginExactly) {
  Timeline t;
  add_delivered(t, ms(5612), "SP");
  const auto at_5s = expect_in(car_received("SP"), Window{Anchor{std::nullopt, 1, seconds(5)}, {}});
  Expectation exactly_at = at_5s;
  exactly_at.window.within = Duration(0);
  EXPECT_TRUE(judged(exactly_at, t).passed);
  EXPECT_FALSE(judged(exactly_at, t, Origin{}).passed) << "from the run's start it is 612 ms late";
  Timeline one_ns_early;
  add_delivered(one_ns_early, ms(5612) - nanoseconds(1), "SP");
  EXPECT_FALSE(judged(exactly_at, one_ns_early).passed);
}

TEST(OriginJudging, AWindowFromTheStartEndsItsLengthAfterTheOriginAndKeepsWhatCameBefore) {
  // `within: 1s` from the start: the connection (just before the origin's
  // record of it) and everything up to 1.612 s are in the window.
  Timeline t;
  t.add(ms(611), ClientKind::connection, {{"state", "connecting"}});
  add_delivered(t, ms(1612), "SP");
  add_delivered(t, ms(1612) + nanoseconds(1), "MV:FWD");
  const Window first_second{Anchor{}, seconds(1)};
  EXPECT_TRUE(judged(expect_in(client_state("connecting"), first_second), t).passed);
  EXPECT_TRUE(judged(expect_in(car_received("SP"), first_second), t).passed);
  EXPECT_FALSE(judged(expect_in(car_received("MV"), first_second), t).passed);
  EXPECT_FALSE(judged(expect_in(car_received("SP"), first_second), t, Origin{}).passed);
}

TEST(OriginJudging, TimesWithoutAWindowCountFromTheOrigin) {
  Timeline t;
  for (const auto at : {ms(6612), ms(8612), ms(11612)})
    t.add(at, ClientKind::connection, {{"state", "connecting"}});
  Expectation e = expect_in(client_state("connecting"), Window{});
  e.quantifier = Quantifier::at_times;
  e.times = {seconds(6), seconds(8), seconds(11)};
  e.only = true;
  EXPECT_TRUE(judged(e, t).passed);
  const auto from_zero = judged(e, t, Origin{});
  EXPECT_FALSE(from_zero.passed);
  EXPECT_NE(from_zero.message.find("nothing at 6.000 s, the nearest at 6.612 s, 0.612 s late"),
            std::string::npos)
      << from_zero.message;
}

TEST(OriginJudging, EventEdgesDoNotMoveWithTheOrigin) {
  Timeline t;
  add_step_end(t, ms(2000), "release");
  add_delivered(t, ms(2250), "MV:STOP");
  EXPECT_TRUE(judged(stop_within_300ms_of_release(), t).passed);
  EXPECT_EQ(judged(stop_within_300ms_of_release(), t).window_from, ms(2000));
}

TEST(OriginJudging, AFailureSaysWhereTheOriginWas) {
  Timeline t;
  add_delivered(t, ms(300), "SP");
  const auto o = judged(
      expect_in(car_received("SP"), Window{Anchor{std::nullopt, 1, seconds(5)}, seconds(1)}), t);
  EXPECT_FALSE(o.passed);
  EXPECT_EQ(o.message,
            "expected at least one 'car received SP' between 5.612 s and 6.612 s (between 5 s "
            "and 6 s from the origin, the client's first connection at +0.612 s), found none; "
            "the nearest at 0.300 s, 5.312 s early");
}

TEST(OriginJudging, AnEventAfterTheSessionsLastRecordIsNotAnAnchor) {
  // What stopping the client caused comes after the session: an anchor on
  // the last disconnect finds the one inside it.
  Timeline t;
  t.add(ms(3000), ClientKind::connection, {{"state", "disconnected"}});
  t.add(ms(9000), ClientKind::connection, {{"state", "disconnected"}});
  const Anchor last{client_state("disconnected"), -1, {}};
  EXPECT_EQ(resolve(last, t, Time(0), ms(8000)), ms(3000));
  EXPECT_EQ(resolve(last, t), ms(9000));
  EXPECT_EQ(resolve(Anchor{std::nullopt, 1, seconds(2)}, t, ms(612)), ms(2612));
}

}  // namespace
}  // namespace hil::harness
