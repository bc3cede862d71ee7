// The scenario runner with the reference clients in virtual time: steps,
// schedule, faults, timeouts and the timeline each run writes, with exact
// times, for all four cars.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "client/logi/core.hpp"
#include "harness/runner.hpp"
#include "harness/scenario_yaml.hpp"
#include "protocol/common/car_profile.hpp"
#include "sim/arena.hpp"
#include "tests/harness/runner_test_support.hpp"

namespace hil::harness {
namespace {

// The scenario pieces and the times they are given in.
using namespace test;
Step wait_until(Matcher m, Duration timeout) {
  std::string text = "wait until " + m.text;
  return step_of(std::move(text), WaitUntilStep{std::move(m), timeout});
}
Step car(std::string text, mocks::Action a) {
  return step_of(text, CarStep{mocks::Behaviour{text, {}, std::move(a)}});
}
Step faults(std::string text, link::FaultProfile p) {
  return step_of(std::move(text), FaultsStep{std::move(p)});
}

Matcher sim_kind(SimKind kind) {
  return Matcher{Source::sim, kind, {}, "sim"};
}
Matcher station(int n) {
  return Matcher{Source::sim, SimKind::station, {{"station", FieldTest::Op::equals, n}}, "station"};
}

Scenario scenario(mocks::CarKind kind, std::vector<Step> steps) {
  Scenario s;
  s.name = "test";
  s.car = kind;
  s.seed = 7;
  s.steps = std::move(steps);
  return s;
}

std::vector<Record> wire(const ScenarioOutcome& o, const std::string& dir,
                         const std::string& stage) {
  std::vector<Record> out;
  for (const auto& r : of(o, WireKind::frame))
    if (r.data["dir"] == dir && r.data["stage"] == stage) out.push_back(r);
  return out;
}

std::optional<Time> step_time(const ScenarioOutcome& o, StepKind kind, const std::string& text) {
  for (const auto& r : of(o, kind))
    if (r.data["text"] == text) return r.at;
  return std::nullopt;
}

std::string steps_summary(const ScenarioOutcome& o) {
  std::string s;
  for (const auto& st : o.steps)
    s += st.phase + " '" + st.text + "' ok=" + (st.ok ? "1" : "0") +
         " ran=" + (st.ran ? "1" : "0") + " " + st.reason + "\n";
  return s;
}

std::vector<Step> manual_drive() {
  return {action("connect"), action("speed 50"), action("mode MAN"), action("press FWD"),
          wait(seconds(1)),  action("release"),  wait(seconds(2))};
}

// ------------------------------------------------------------------ LOGI

TEST(RunnerLogi, ReleaseSendsMvStopAtTheReleaseStepsExactTimeAndTheCarComesToRest) {
  Scenario s = scenario(mocks::CarKind::logi, manual_drive());
  Expectation stop_received;
  stop_received.line = 1;
  stop_received.what = Matcher{Source::wire,
                               WireKind::frame,
                               {{"dir", FieldTest::Op::equals, "to_car"},
                                {"stage", FieldTest::Op::equals, "delivered"},
                                {"frame", FieldTest::Op::kind_prefix, "MV:STOP"}},
                               "car received MV:STOP"};
  stop_received.window.from.event = Matcher{
      Source::step, StepKind::start, {{"text", FieldTest::Op::equals, "release"}}, "step release"};
  stop_received.window.within = milliseconds(300);
  s.expectations.push_back(stop_received);

  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.error.empty()) << o.error;
  ASSERT_TRUE(o.passed()) << o.first_failure() << "\n" << steps_summary(o);
  EXPECT_EQ(o.seed, 7u);
  EXPECT_EQ(o.repro_command, "hil run test --seed 7");

  const auto release = step_time(o, StepKind::start, "release");
  ASSERT_TRUE(release);
  std::vector<Time> stops;
  for (const auto& r : wire(o, "to_car", "delivered"))
    if (r.data["frame"] == "MV:STOP") stops.push_back(r.at);
  ASSERT_FALSE(stops.empty());
  EXPECT_EQ(stops.front(), *release) << "no latency on mem://, none added by the runner";
  const auto press = step_time(o, StepKind::start, "press FWD");
  ASSERT_TRUE(press);
  EXPECT_EQ(*release - *step_time(o, StepKind::start, "wait"), seconds(1))
      << "the 1 s wait ends exactly when the release begins";

  // Motion between press and release, rest after.
  const auto moving = of(o, SimKind::moving);
  const auto rest = of(o, SimKind::at_rest);
  ASSERT_EQ(moving.size(), 1u);
  ASSERT_EQ(rest.size(), 2u) << "at the start, and after the release";
  EXPECT_GT(moving[0].at, *press);
  EXPECT_LT(moving[0].at, *release);
  EXPECT_GT(rest[1].at, *release);
  EXPECT_LT(rest[1].at, *release + seconds(1));
  double fastest = 0;
  for (const auto& r : of(o, SimKind::sample))
    fastest = std::max(fastest, r.data["speed_mps"].get<double>());
  EXPECT_GT(fastest, 0.05);
  EXPECT_EQ(of(o, SimKind::sample).back().data["speed_mps"], 0.0);

  // The client's own story: connected, and its commands accepted.
  const auto connections = of(o, ClientKind::connection);
  ASSERT_GE(connections.size(), 2u);
  EXPECT_EQ(connections[1].data["state"], "connected");
  std::vector<std::string> accepted;
  for (const auto& r : of(o, ClientKind::command))
    if (r.data["state"] == "accepted") accepted.push_back(r.data["command"]);
  EXPECT_EQ(accepted, (std::vector<std::string>{"SP", "MD:MAN", "MV:FWD", "MV:STOP"}));
  const auto actions = of(o, ClientKind::action);
  ASSERT_EQ(actions.size(), 5u);
  for (const auto& a : actions)
    EXPECT_TRUE(a.data["ok"].get<bool>()) << a.data.dump();

  // Every sample is on the 100 ms grid.
  for (const auto& r : of(o, SimKind::sample))
    EXPECT_EQ(r.at.count() % milliseconds(100).count(), 0) << link::format_ms(r.at);
  EXPECT_FALSE(o.trajectories.empty());
  EXPECT_GT(o.trajectories[0].samples.size(), 10u);
}

TEST(RunnerLogi, TheSameSeedGivesTheSameTimelineRecordForRecord) {
  Scenario s = scenario(mocks::CarKind::logi, manual_drive());
  link::FaultRule split;
  split.direction = link::DirectionFilter::to_client;
  split.trigger.probability = 0.5;
  split.action = link::Fragment{{1, 4}, {milliseconds(0), milliseconds(3)}};
  s.faults.rules.push_back(split);
  const auto a = run_scenario(s);
  const auto b = run_scenario(s);
  ASSERT_GT(a.timeline.size(), 100u);
  EXPECT_EQ(a.timeline.to_ndjson(), b.timeline.to_ndjson());
  RunOptions other;
  other.seed = 8;
  const auto c = run_scenario(s, other);
  EXPECT_EQ(c.seed, 8u);
  EXPECT_NE(a.timeline.to_ndjson(), c.timeline.to_ndjson()) << "another seed, other faults";
}

// The LOGI profile's processing time: every byte the car sends, and so a
// hang-up that follows them, leaves this long after what made it.
const link::Duration kLogiLatency =
    std::chrono::duration_cast<link::Duration>(protocol::default_car_profile("logi").reply_latency);

TEST(RunnerLogi, AfterTheCarHangsUpAt5sTheClientReconnectsAt6s) {
  // The hang-up waits for the STAT of 5 s, which leaves after the car's
  // latency; the client's backoff of 1 s counts from there.
  Scenario s = scenario(mocks::CarKind::logi, {action("connect"), wait(seconds(8))});
  s.schedule.push_back(
      ScheduledStep{Anchor{std::nullopt, 1, seconds(5)},
                    car("hang up", mocks::CloseConnection{link::CloseMode::graceful})});
  const auto o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << o.first_failure();
  std::vector<std::pair<Time, std::string>> states;
  for (const auto& r : of(o, ClientKind::connection))
    states.emplace_back(r.at, r.data["state"]);
  const std::vector<std::pair<Time, std::string>> expected = {
      {Time(0), "connecting"},
      {Time(0), "connected"},
      {seconds(5) + kLogiLatency, "reconnecting"},
      {seconds(6) + kLogiLatency, "connecting"},
      {seconds(6) + kLogiLatency, "connected"},
      {o.session_end, "disconnected"},  // the run stopped the client
  };
  EXPECT_EQ(o.session_end, seconds(8) + milliseconds(500)) << "the steps, then the settle";
  EXPECT_EQ(states, expected);
  const auto behaviours = of(o, CarEventKind::behaviour);
  ASSERT_EQ(behaviours.size(), 1u);
  EXPECT_EQ(behaviours[0].at, seconds(5));
  EXPECT_EQ(o.steps.back().phase, "schedule");
  EXPECT_TRUE(o.steps.back().ran);
  EXPECT_EQ(o.steps.back().started, seconds(5));
}

TEST(RunnerLogi, RefusedConnectionsAreFaultRecordsAndTheClientGetsBackInWhenTheyEnd) {
  // The car hangs up at 5 s and refuses connections until 10.5 s. A refusal
  // is an accept and a reset, as over TCP; the car said nothing on those
  // connections, so the client keeps backing off: 6 s, 8 s, then 11 s, where
  // it stays, each plus the car's latency (the hang-up follows the STAT of
  // 5 s out).
  Scenario s = scenario(mocks::CarKind::logi, {action("connect"), wait(seconds(12))});
  link::FaultRule refuse;
  refuse.name = "unreachable";
  refuse.trigger.at = seconds(5);
  refuse.action = link::Refuse{milliseconds(5500)};
  s.faults.rules.push_back(refuse);
  s.schedule.push_back(
      ScheduledStep{Anchor{std::nullopt, 1, seconds(5)}, car("hang up", mocks::CloseConnection{})});
  const auto o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << o.first_failure();
  std::vector<Time> attempts;
  for (const auto& r : of(o, ClientKind::connection))
    if (r.data["state"] == "connecting" && r.at > seconds(5)) attempts.push_back(r.at);
  EXPECT_EQ(attempts, (std::vector<Time>{seconds(6) + kLogiLatency, seconds(8) + kLogiLatency,
                                         seconds(11) + kLogiLatency}));
  std::vector<Time> refused;
  for (const auto& r : of(o, link::FaultKind::refuse)) {
    refused.push_back(r.at);
    EXPECT_EQ(r.data["rule"], "unreachable");
  }
  EXPECT_EQ(refused, (std::vector<Time>{seconds(6) + kLogiLatency, seconds(8) + kLogiLatency}));
  const auto opens = of(o, WireKind::open);
  ASSERT_EQ(opens.size(), 2u) << "a refused connection gets no link";
  EXPECT_EQ(opens[1].at, seconds(11) + kLogiLatency);
  EXPECT_EQ(in_session(o, ClientKind::connection).back().data["state"], "connected");
}

TEST(RunnerLogi, AnAutoRunReachesStation2AndTheCarStopsThere) {
  Scenario s = scenario(mocks::CarKind::logi,
                        {action("connect"), action("speed 60"), action("mode AUTO"),
                         action("station 2"), action("run"), wait_until(station(2), seconds(90)),
                         wait_until(sim_kind(SimKind::at_rest), seconds(5))});
  Expectation at_rest;
  at_rest.line = 9;
  at_rest.what = sim_kind(SimKind::at_rest);
  at_rest.window.from.event = station(2);
  at_rest.window.within = seconds(2);
  s.expectations.push_back(at_rest);
  const auto o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << o.first_failure() << "\n" << steps_summary(o);
  const auto stations = of(o, SimKind::station);
  ASSERT_FALSE(stations.empty());
  EXPECT_EQ(stations.back().data["station"], 2);
  EXPECT_EQ(stations.back().data["tag"], "002");
  EXPECT_LT(o.run_time, seconds(90));
  EXPECT_EQ(of(o, SimKind::sample).back().data["speed_mps"], 0.0);
}

TEST(RunnerLogi, ARejectedCommandFailsItsStepStopsTheSequenceAndTeardownStillRuns) {
  Scenario s =
      scenario(mocks::CarKind::logi, {action("connect"), car("refuse SP", mocks::Reject{"SP", 5}),
                                      action("speed 50"), action("mode MAN")});
  s.teardown = {action("disconnect")};
  const auto o = run_scenario(s);
  EXPECT_FALSE(o.passed());
  ASSERT_EQ(o.steps.size(), 5u);
  EXPECT_TRUE(o.steps[0].ok);
  EXPECT_TRUE(o.steps[1].ok);
  EXPECT_FALSE(o.steps[2].ok);
  EXPECT_TRUE(o.steps[2].ran);
  EXPECT_FALSE(o.steps[2].reason.empty());
  EXPECT_FALSE(o.steps[3].ran);
  EXPECT_FALSE(o.steps[3].ok);
  EXPECT_EQ(o.steps[3].reason, "not run: the step on line 0 failed");
  EXPECT_EQ(o.steps[4].phase, "teardown");
  EXPECT_TRUE(o.steps[4].ran);
  EXPECT_TRUE(o.steps[4].ok) << o.steps[4].reason;
  EXPECT_EQ(o.first_failure().rfind("step line 0 (speed 50): ", 0), 0u) << o.first_failure();
  EXPECT_FALSE(step_time(o, StepKind::start, "mode MAN"));
  const auto rejected =
      std::count_if(o.timeline.records().begin(), o.timeline.records().end(), [](const Record& r) {
        return r.kind == ClientKind::command && r.data["state"] == "rejected";
      });
  EXPECT_GE(rejected, 1);
}

TEST(RunnerLogi, FaultsFromTheStartAreRecordedUntilAFaultsStepTurnsThemOff) {
  Scenario s =
      scenario(mocks::CarKind::logi, {action("connect"), wait(seconds(2)), faults("faults off", {}),
                                      action("speed 50"), wait(seconds(2))});
  link::FaultRule split;
  split.name = "split";
  split.direction = link::DirectionFilter::to_client;
  split.trigger.match = "STAT";
  split.action = link::Fragment{{2, 4}, {milliseconds(1), milliseconds(1)}};
  link::FaultRule corrupt;
  corrupt.name = "bad checksum";
  corrupt.direction = link::DirectionFilter::to_client;
  corrupt.trigger.match = "STAT";
  corrupt.trigger.first = 1;
  corrupt.action = link::Corrupt{link::CorruptTarget::checksum, {}, 1};
  s.faults.rules = {corrupt, split};
  const auto o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << o.first_failure() << "\n" << steps_summary(o);
  const auto off = step_time(o, StepKind::end, "faults off");
  ASSERT_TRUE(off);
  const auto fragments = of(o, link::FaultKind::fragment);
  const auto corrupted = of(o, link::FaultKind::corrupt);
  ASSERT_GE(fragments.size(), 3u);
  ASSERT_EQ(corrupted.size(), 1u);
  EXPECT_EQ(corrupted[0].data["rule"], "bad checksum");
  EXPECT_EQ(corrupted[0].data["dir"], "to_client");
  for (const auto& f : of(o, link::FaultKind::fragment))
    EXPECT_LT(f.at, *off) << link::format_ms(f.at);
  // The corrupted STAT reached the client invalid; what was sent was fine.
  bool invalid_delivered = false;
  for (const auto& r : wire(o, "to_client", "delivered")) {
    if (!r.data["valid"].get<bool>()) {
      invalid_delivered = true;
      EXPECT_EQ(r.data["error"], "bad_checksum");
    }
  }
  EXPECT_TRUE(invalid_delivered);
  for (const auto& r : wire(o, "to_client", "sent"))
    EXPECT_TRUE(r.data["valid"].get<bool>());
  EXPECT_FALSE(of(o, ClientKind::parse_error).empty());
}

TEST(RunnerLogi, ARunThatOutlivesItsTimeoutFailsTheRestAndStillTearsDown) {
  Scenario s =
      scenario(mocks::CarKind::logi, {action("connect"), wait(seconds(10)), action("speed 50")});
  s.timeout = seconds(3);
  s.teardown = {action("disconnect")};
  const auto o = run_scenario(s);
  ASSERT_EQ(o.steps.size(), 4u);
  EXPECT_TRUE(o.steps[0].ok);
  EXPECT_FALSE(o.steps[1].ok);
  EXPECT_EQ(o.steps[1].reason, "timed out after 3 s");
  EXPECT_EQ(o.steps[1].ended, seconds(3));
  EXPECT_FALSE(o.steps[2].ran);
  EXPECT_EQ(o.steps[2].reason, "timed out after 3 s");
  EXPECT_TRUE(o.steps[3].ok);
  EXPECT_EQ(o.steps[3].started, seconds(3));
  EXPECT_EQ(o.session_end, seconds(3) + milliseconds(500)) << "teardown at once, then the settle";
  EXPECT_EQ(o.run_time, o.session_end + seconds(1)) << "then 1 s to judge the car at rest";
}

TEST(RunnerLogi, AWaitUntilThatNeverMatchesFailsAfterItsTimeout) {
  Scenario s =
      scenario(mocks::CarKind::logi, {action("connect"), wait_until(station(2), seconds(2))});
  const auto o = run_scenario(s);
  ASSERT_EQ(o.steps.size(), 2u);
  EXPECT_FALSE(o.steps[1].ok);
  EXPECT_EQ(o.steps[1].reason, "no 'station' within 2 s");
  EXPECT_EQ(o.steps[1].ended - o.steps[1].started, seconds(2));
}

TEST(RunnerLogi, AStepScheduledOnAnEventStartsAtTheEventPlusItsOffset) {
  Scenario s =
      scenario(mocks::CarKind::logi, {action("connect"), action("speed 50"), wait(seconds(3))});
  Matcher sp{Source::wire,
             WireKind::frame,
             {{"dir", FieldTest::Op::equals, "to_car"},
              {"stage", FieldTest::Op::equals, "delivered"},
              {"frame", FieldTest::Op::kind_prefix, "SP"}},
             "car received SP"};
  s.schedule.push_back(ScheduledStep{Anchor{sp, 1, milliseconds(1200)},
                                     car("mute", mocks::MuteTelemetry{seconds(10)})});
  const auto o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << o.first_failure();
  std::optional<Time> received;
  for (const auto& r : wire(o, "to_car", "delivered"))
    if (r.data["frame"] == "SP" && !received) received = r.at;
  ASSERT_TRUE(received);
  EXPECT_EQ(o.steps.back().started, *received + milliseconds(1200));
  // Muted: no STAT after the step, and the client says so as soon as more
  // than 2 s have passed since the last (one tick of its clock later).
  std::optional<Time> last_stat;
  for (const auto& r : wire(o, "to_client", "sent"))
    if (r.data["frame"] == "STAT") last_stat = r.at;
  ASSERT_TRUE(last_stat);
  EXPECT_EQ(*last_stat, seconds(1) + kLogiLatency)
      << "STAT every 500 ms, each after the car's latency, until the mute at 1.2 s";
  const auto stale = of(o, ClientKind::stale);
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_EQ(stale[0].at, *last_stat + seconds(2) + client::logi::LogiClientCore::kTick);
}

TEST(RunnerOtherCars, AnObstaclePutAheadOfTheWr8IsHitAndCanBeTakenAway) {
  Scenario s = scenario(
      mocks::CarKind::wr8,
      {action("connect"), step_of("parcel", ObstacleStep{true, 0.05, "parcel"}),
       action("drive 100"), wait(seconds(1)), step_of("lift", ObstacleStep{false, 0, "parcel"})});
  const auto o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << o.first_failure() << "\n" << steps_summary(o);
  const auto hits = of(o, SimKind::collision);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].data["with"], "parcel");
  const auto rest = of(o, SimKind::at_rest);
  ASSERT_EQ(rest.size(), 2u);
  EXPECT_GE(rest[1].at, hits[0].at);
  ASSERT_EQ(o.arena.obstacles.size(), 1u + sim::default_warehouse_arena().obstacles.size());

  Scenario lift_nothing =
      scenario(mocks::CarKind::logi, {step_of("lift", ObstacleStep{false, 0, "parcel"})});
  EXPECT_EQ(run_scenario(lift_nothing).first_failure(),
            "step line 0 (lift): no obstacle named 'parcel' to take away");
}

// ------------------------------------------------------------ other cars

void expect_frames_both_ways(const ScenarioOutcome& o) {
  EXPECT_FALSE(wire(o, "to_car", "delivered").empty());
  EXPECT_FALSE(wire(o, "to_client", "delivered").empty());
  for (const auto& r : of(o, WireKind::frame))
    EXPECT_TRUE(r.data["valid"].get<bool>()) << r.data.dump();
}

TEST(RunnerOtherCars, Wr8LogsInAndDrives30cm) {
  const auto o =
      run_scenario(scenario(mocks::CarKind::wr8, {action("connect"), action("drive 30")}));
  ASSERT_TRUE(o.passed()) << o.first_failure() << "\n" << steps_summary(o);
  expect_frames_both_ways(o);
  bool auth = false;
  for (const auto& r : wire(o, "to_car", "delivered"))
    if (r.data["frame"] == "AUTH") auth = true;
  EXPECT_TRUE(auth);
  ASSERT_FALSE(of(o, ClientKind::login).empty());
  EXPECT_EQ(of(o, ClientKind::login)[0].data["ok"], true);
  EXPECT_FALSE(of(o, SimKind::moving).empty());
}

TEST(RunnerOtherCars, ArduinoAnswersPingSpeedAndStatus) {
  const auto o = run_scenario(
      scenario(mocks::CarKind::arduino, {action("PING"), action("V 160"), action("STATUS")}));
  ASSERT_TRUE(o.passed()) << o.first_failure() << "\n" << steps_summary(o);
  expect_frames_both_ways(o);
  EXPECT_EQ(of(o, ClientKind::connection).front().data["state"], "connecting");
  EXPECT_EQ(in_session(o, ClientKind::command).size(), 3u);
  EXPECT_EQ(of(o, ClientKind::command).size(), 4u)
      << "and the S (stop) the client sends when the run stops it";
}

TEST(RunnerOtherCars, LekaRunsAGroupAndAnswersInfo) {
  const auto o =
      run_scenario(scenario(mocks::CarKind::leka, {action("ear all 255 0 0"), action("info")}));
  ASSERT_TRUE(o.passed()) << o.first_failure() << "\n" << steps_summary(o);
  expect_frames_both_ways(o);
  const auto connected = of(o, ClientKind::connection).front();
  EXPECT_EQ(connected.data["state"], "connected");
  EXPECT_EQ(connected.at, Time(0));
}

TEST(RunnerOtherCars, AnUnknownActionFailsItsStepWithTheParsersWords) {
  const auto o = run_scenario(scenario(mocks::CarKind::arduino, {action("FLY 3")}));
  ASSERT_EQ(o.steps.size(), 1u);
  EXPECT_FALSE(o.steps[0].ok);
  EXPECT_NE(o.steps[0].reason.find("column 1"), std::string::npos) << o.steps[0].reason;
}

// ------------------------------------------------------------------ other

TEST(Runner, AWorldThatCannotBeBuiltIsTheRunsError) {
  Scenario s = scenario(mocks::CarKind::logi, {action("connect")});
  s.world = "/nonexistent/world.yaml";
  const auto o = run_scenario(s);
  EXPECT_EQ(o.error.rfind("the world cannot be built: ", 0), 0u) << o.error;
  EXPECT_FALSE(o.passed());
}

TEST(Runner, ASettingOfTheReferenceClientSkipsTheScenarioForAnExternalProgram) {
  Scenario s = scenario(mocks::CarKind::logi, {action("connect")});
  s.client = ReferenceClient{false, {{"keepalive", true}, {"keepalive_period", "300ms"}}};
  RunOptions exec;
  // A program that would fail the run at once: the skip starts nothing.
  exec.client_exec = "false";
  const auto why = skip_reason(s, exec);
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("keepalive, keepalive_period"), std::string::npos) << *why;
  EXPECT_NE(why->find("--client-exec"), std::string::npos) << *why;

  const auto o = run_scenario(s, exec);
  EXPECT_TRUE(o.was_skipped());
  EXPECT_EQ(o.skipped, *why);
  EXPECT_TRUE(o.passed()) << "a skipped scenario fails nothing";
  EXPECT_TRUE(o.steps.empty());
  EXPECT_EQ(o.timeline.size(), 0u) << "nothing ran";
  EXPECT_TRUE(o.error.empty()) << o.error;

  // hil's own client takes the settings, and no settings skips nothing.
  EXPECT_FALSE(skip_reason(s, RunOptions{}).has_value());
  EXPECT_FALSE(run_scenario(s).was_skipped());
  s.client = ReferenceClient{};
  EXPECT_FALSE(skip_reason(s, exec).has_value());
}

TEST(Runner, WithoutASeedOneIsChosenAndPrintedInTheReproCommand) {
  Scenario s = scenario(mocks::CarKind::logi, {});
  s.seed.reset();
  s.file = "scenarios/x.yaml";
  const auto o = run_scenario(s);
  EXPECT_EQ(o.repro_command, "hil run scenarios/x.yaml --seed " + std::to_string(o.seed));
  EXPECT_EQ(o.session_end, milliseconds(500)) << "no steps: the settle alone";
  EXPECT_EQ(o.run_time, milliseconds(1500)) << "then 1 s to judge the car at rest";
}

TEST(Runner, TheExampleScenariosPassWithTheReferenceClient) {
  const auto folder = std::filesystem::path(HIL_SOURCE_DIR) / "scenarios" / "examples";
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    if (entry.path().extension() == ".yaml") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty());
  for (const auto& file : files) {
    const Scenario s = load_scenario(file);
    const auto o = run_scenario(s);
    EXPECT_TRUE(o.passed()) << file << ": " << o.first_failure() << "\n" << steps_summary(o);
  }
}

// ------------------------------------------------------- expected failures

Step must_fail(Step step, std::string contains = "") {
  step.expect_failure = true;
  step.failure_contains = std::move(contains);
  return step;
}

Matcher never_seen() {
  return client_record(ClientKind::notice, "text", "no such notice", "a notice that never comes");
}

TEST(RunnerExpectedFailure, AStepThatFailsAsExpectedPassesAndTheSequenceGoesOn) {
  Scenario s = scenario(
      mocks::CarKind::logi,
      {must_fail(wait_until(never_seen(), seconds(1)), "within 1 s"), wait(milliseconds(10))});
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << steps_summary(o);
  EXPECT_EQ(o.steps[0].reason, "failed as expected: no 'a notice that never comes' within 1 s");
  EXPECT_TRUE(o.steps[1].ran);
  EXPECT_EQ(o.steps[1].started, Time(0) + seconds(1));
}

TEST(RunnerExpectedFailure, FailingForAnotherReasonFailsTheStep) {
  Scenario s = scenario(mocks::CarKind::logi,
                        {must_fail(wait_until(never_seen(), seconds(1)), "Not in manual mode")});
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_FALSE(o.passed());
  EXPECT_FALSE(o.steps[0].ok);
  EXPECT_EQ(o.steps[0].reason,
            "failed, but not with 'Not in manual mode': no 'a notice that never comes' within 1 s");
}

TEST(RunnerExpectedFailure, SucceedingFailsTheStep) {
  Scenario s =
      scenario(mocks::CarKind::logi, {must_fail(wait(milliseconds(10))), wait(seconds(1))});
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_FALSE(o.passed());
  EXPECT_FALSE(o.steps[0].ok);
  EXPECT_EQ(o.steps[0].reason, "expected to fail, but it succeeded");
  EXPECT_FALSE(o.steps[1].ran) << "a failed step stops the sequence";
}

TEST(RunnerExpectedFailure, TheRunTimingOutIsNotTheFailureThatWasExpected) {
  Scenario s = scenario(mocks::CarKind::logi, {must_fail(wait_until(never_seen(), seconds(60)))});
  s.timeout = seconds(2);
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_FALSE(o.passed());
  EXPECT_FALSE(o.steps[0].ok);
  EXPECT_EQ(o.steps[0].reason, "timed out after 2 s");
}

// ----------------------------------------------- actions beside each other

std::vector<Time> received_at(const ScenarioOutcome& o, const std::string& frame) {
  std::vector<Time> out;
  for (const auto& r : wire(o, "to_car", "delivered"))
    if (r.data["frame"] == frame && r.data["valid"] == true) out.push_back(r.at);
  return out;
}

TEST(RunnerConcurrentActions, AScheduledEmergencyStopGoesOutBesideAnActionUnderWay) {
  // The car swallows SP, so `speed 60` waits through its retries for
  // seconds; the emergency stop scheduled 300 ms into it must not wait.
  Scenario s = scenario(mocks::CarKind::logi,
                        {action("connect"), action("mode MAN"),
                         car("swallow SP", mocks::Ignore{"SP", std::nullopt, std::nullopt}),
                         must_fail(action("speed 60")), wait(milliseconds(100))});
  const Matcher speed_starts{Source::step,
                             StepKind::start,
                             {{"text", FieldTest::Op::equals, "speed 60"}},
                             "speed 60 starts"};
  s.schedule.push_back(ScheduledStep{Anchor{speed_starts, 1, milliseconds(300)}, action("estop")});
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << o.first_failure() << "\n" << steps_summary(o);

  const auto speed = step_time(o, StepKind::start, "speed 60");
  ASSERT_TRUE(speed);
  const auto stops = received_at(o, "MV:STOP");
  ASSERT_FALSE(stops.empty());
  EXPECT_EQ(stops.front(), *speed + milliseconds(300));
  const auto speed_end = step_time(o, StepKind::end, "speed 60");
  ASSERT_TRUE(speed_end);
  EXPECT_GT(*speed_end, stops.front() + seconds(1)) << "the SP was still under way";
  const auto estop_end = step_time(o, StepKind::end, "estop");
  ASSERT_TRUE(estop_end);
  EXPECT_LT(*estop_end, *speed_end);
}

TEST(RunnerConcurrentActions, ConfirmResendsTheUncertainRunOfAnEarlierStep) {
  Scenario s =
      scenario(mocks::CarKind::logi,
               {action("connect"), action("speed 50"), action("mode AUTO"), action("station 1"),
                car("swallow ST:RUN", mocks::Ignore{"ST:RUN", 1, std::nullopt}),
                must_fail(action("run"), "uncertain"), action("confirm"), wait(milliseconds(100))});
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << o.first_failure() << "\n" << steps_summary(o);
  const auto confirm = step_time(o, StepKind::start, "confirm");
  ASSERT_TRUE(confirm);
  const auto runs = received_at(o, "ST:RUN");
  ASSERT_EQ(runs.size(), 2u)
      << "one swallowed (ST:RUN is not retried by itself), then the confirmed resend";
  EXPECT_EQ(runs.back(), *confirm);
}

}  // namespace
}  // namespace hil::harness
