// Scenario files as QA writes them: every key and step becomes the model the
// runner and the checker read, and every mistake is reported at its file,
// line and column (matchers, windows and quantifiers:
// scenario_yaml_matchers_test.cpp).

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "harness/scenario_yaml.hpp"
#include "tests/harness/scenario_yaml_support.hpp"

namespace hil::harness {
namespace {

using namespace test;

// ------------------------------------------ the six release checks of docs/scenarios.md

TEST(ScenarioYamlReleaseChecks, MvStopWithin300msOfTheRelease) {
  const auto s = logi(R"(expect:
  - received: "MV:STOP"
    within: 300ms
    after: {step: release, at: start}
)");
  ASSERT_EQ(s.expectations.size(), 1u);
  const auto& e = s.expectations[0];
  EXPECT_EQ(e.line, 13);
  EXPECT_EQ(e.what, car_received("MV:STOP"));
  EXPECT_EQ(e.quantifier, Quantifier::exists);
  EXPECT_EQ(e.window.from.event, step_started("release"));
  EXPECT_EQ(e.window.from.occurrence, 1);
  EXPECT_EQ(e.window.from.offset, Duration{0});
  EXPECT_EQ(e.window.within, milliseconds(300));
  EXPECT_EQ(e.label, "car received MV:STOP within 300ms after step 'release' started");
}

TEST(ScenarioYamlReleaseChecks, ReconnectAttemptsAt6s8s11sEachWithin250ms) {
  const auto s = logi(R"(schedule:
  - at: 5s
    faults: {rules: [{kind: reset, at: 5s}, {kind: refuse, at: 5s, for: 5500ms}]}
expect:
  - label: reconnect attempts at 6 s, 8 s and 11 s
    client: connecting
    times: [6s, 8s, 11s]
    tolerance: 250ms
)");
  ASSERT_EQ(s.expectations.size(), 1u);
  const auto& e = s.expectations[0];
  EXPECT_EQ(e.what, (Matcher{Source::client,
                             ClientKind::connection,
                             {{"state", Op::equals, "connecting"}},
                             "client connecting"}));
  EXPECT_EQ(e.quantifier, Quantifier::at_times);
  EXPECT_EQ(e.times, (std::vector<Duration>{seconds(6), seconds(8), seconds(11)}));
  EXPECT_EQ(e.tolerance, milliseconds(250));
  EXPECT_FALSE(e.only);
  EXPECT_EQ(e.window, Window{});  // from the start of the run, to its end
  EXPECT_EQ(e.label, "reconnect attempts at 6 s, 8 s and 11 s");
  ASSERT_EQ(s.schedule.size(), 1u);
  EXPECT_EQ(s.schedule[0].when, (Anchor{std::nullopt, 1, seconds(5)}));
  const auto& faults = std::get<FaultsStep>(s.schedule[0].step.action);
  EXPECT_EQ(faults.profile.rules.size(), 2u);
}

TEST(ScenarioYamlReleaseChecks, ExactlyOneStRunReceived) {
  const auto s = logi(R"(expect:
  - received: "ST:RUN"
    count: 1
)");
  const auto& e = s.expectations.at(0);
  EXPECT_EQ(e.what, car_received("ST:RUN"));
  EXPECT_EQ(e.quantifier, Quantifier::exactly);
  EXPECT_EQ(e.count, 1u);
  EXPECT_EQ(e.window, Window{});
  EXPECT_EQ(e.label, "exactly 1 x car received ST:RUN");
}

TEST(ScenarioYamlReleaseChecks, Station2Within90sAndStopped) {
  const auto s = logi(R"(expect:
  - sim: {station: 2}
    within: 90s
  - sim: at_rest
    after: {sim: {station: 2}}
    within: 2s
)");
  ASSERT_EQ(s.expectations.size(), 2u);
  const Matcher station{
      Source::sim, SimKind::station, {{"station", Op::equals, 2}}, "car reached station 2"};
  EXPECT_EQ(s.expectations[0].what, station);
  EXPECT_EQ(s.expectations[0].window, (Window{Anchor{}, seconds(90)}));
  EXPECT_EQ(s.expectations[1].what,
            (Matcher{Source::sim, SimKind::at_rest, {}, "chassis at rest"}));
  EXPECT_EQ(s.expectations[1].window, (Window{Anchor{station, 1, Duration{0}}, seconds(2)}));
}

TEST(ScenarioYamlReleaseChecks, ClientNeverSentABadChecksum) {
  const auto s = logi(R"(expect:
  - never: true
    wire: {sent_by_client: "*", valid: false, error: checksum}
)");
  const auto& e = s.expectations.at(0);
  EXPECT_EQ(e.quantifier, Quantifier::never);
  EXPECT_EQ(e.what, (Matcher{Source::wire,
                             WireKind::frame,
                             {{"dir", Op::equals, "to_car"},
                              {"stage", Op::equals, "sent"},
                              {"valid", Op::equals, false},
                              {"error", Op::contains, "checksum"}},
                             "client sent a frame (invalid) with error checksum"}));
  EXPECT_EQ(e.window, Window{});
}

TEST(ScenarioYamlReleaseChecks, AtRestWithin1sOfTheEmergencyStop) {
  const auto s = logi(R"(expect:
  - sim: at_rest
    within: 1s
    after: {step: estop, at: start}
)");
  const auto& e = s.expectations.at(0);
  EXPECT_EQ(e.what.source, Source::sim);
  EXPECT_EQ(e.what.kind, SimKind::at_rest);
  EXPECT_TRUE(e.what.tests.empty());
  EXPECT_EQ(e.window, (Window{Anchor{step_started("estop"), 1, Duration{0}}, seconds(1)}));
  EXPECT_EQ(e.label, "chassis at rest within 1s after step 'estop' started");
}

TEST(ScenarioYamlReleaseChecks, AllSixTogetherInOneFile) {
  const auto s = load_scenario(kData + "/release-checks.yaml");
  ASSERT_EQ(s.expectations.size(), 7u);
  std::vector<Quantifier> quantifiers;
  for (const auto& e : s.expectations)
    quantifiers.push_back(e.quantifier);
  EXPECT_EQ(quantifiers,
            (std::vector<Quantifier>{Quantifier::exists, Quantifier::at_times, Quantifier::exactly,
                                     Quantifier::exists, Quantifier::exists, Quantifier::never,
                                     Quantifier::exists}));
  EXPECT_EQ(s.expectations[0].line, 24);
  EXPECT_EQ(s.expectations[0].window.from.event, step_started("release"));
  EXPECT_EQ(s.expectations[6].window.from.event, step_started("estop"));
  EXPECT_EQ(std::get<WaitUntilStep>(s.steps.at(6).action).timeout, seconds(90));
}

// ------------------------------------------------------------ top-level keys

TEST(ScenarioYaml, AMinimalScenarioTakesTheDefaults) {
  const auto s = parse("name: smallest\ncar: wr8\nsteps: [connect]\n");
  EXPECT_EQ(s.name, "smallest");
  EXPECT_EQ(s.file, "t.yaml");
  EXPECT_EQ(s.car, mocks::CarKind::wr8);
  EXPECT_EQ(s.world, "");
  EXPECT_FALSE(s.seed.has_value());
  EXPECT_EQ(s.timeout, seconds(120));
  EXPECT_EQ(s.settle, milliseconds(500));
  EXPECT_EQ(s.at_end, AtEnd::at_rest);
  EXPECT_EQ(s.client, ClientSpec{ReferenceClient{}});
  EXPECT_TRUE(s.faults.rules.empty());
  ASSERT_EQ(s.steps.size(), 1u);
  EXPECT_EQ(s.steps[0], step_of(3, "connect", ActionStep{"connect"}));
  EXPECT_TRUE(s.expectations.empty());
}

TEST(ScenarioYaml, ReadsEveryTopLevelKey) {
  const auto s = parse(
      "name: release-sends-stop\n"
      "description: Releasing a direction in MAN sends MV:STOP at once\n"
      "tags: [logi, safety, dod-5.3]\n"
      "car: logi\n"
      "seed: 42\n"
      "timeout: 60s\n"
      "settle: 250ms\n"
      "at_end: moving\n"
      "client: {reference: {real_time: true}}\n"
      "faults:\n"
      "  rules:\n"
      "    - kind: delay\n"
      "      delay: 40ms\n"
      "setup: [connect]\n"
      "steps: [speed 50]\n"
      "teardown: [disconnect]\n");
  EXPECT_EQ(s.description, "Releasing a direction in MAN sends MV:STOP at once");
  EXPECT_EQ(s.tags, (std::vector<std::string>{"logi", "safety", "dod-5.3"}));
  EXPECT_EQ(s.seed, 42u);
  EXPECT_EQ(s.timeout, seconds(60));
  EXPECT_EQ(s.settle, milliseconds(250));
  EXPECT_EQ(s.at_end, AtEnd::moving);
  EXPECT_EQ(s.client, ClientSpec{ReferenceClient{true}});
  ASSERT_EQ(s.faults.rules.size(), 1u);
  EXPECT_EQ(s.setup.at(0).text, "connect");
  EXPECT_EQ(s.steps.at(0).text, "speed 50");
  EXPECT_EQ(s.teardown.at(0).text, "disconnect");
}

TEST(ScenarioYaml, ExecClientKeepsItsCommandAndStartupTimeout) {
  const auto s = parse(
      "name: t\ncar: logi\nsteps: [connect]\n"
      "client: {exec: \"./my-client --host {host} --port {port} --script {actions}\", "
      "startup_timeout: 3s}\n");
  EXPECT_EQ(s.client,
            ClientSpec{(ExecClient{"./my-client --host {host} --port {port} --script {actions}",
                                   seconds(3)})});
  EXPECT_EQ(parse("name: t\ncar: logi\nsteps: [connect]\nclient: reference\n").client,
            ClientSpec{ReferenceClient{}});
}

TEST(ScenarioYaml, ReferenceClientSettingsAreCheckedByTheCarsClientLibrary) {
  const auto logi_client = std::get<ReferenceClient>(
      parse("name: t\ncar: logi\nsteps: [connect]\n"
            "client:\n"
            "  reference:\n"
            "    real_time: true\n"
            "    settings: {max_retries: 0, keepalive: on, reconnect_delays: [1s, 500ms]}\n")
          .client);
  EXPECT_TRUE(logi_client.real_time);
  EXPECT_EQ(logi_client.settings,
            (nlohmann::json{
                {"max_retries", "0"}, {"keepalive", "on"}, {"reconnect_delays", {"1s", "500ms"}}}));
  EXPECT_EQ(std::get<ReferenceClient>(
                parse("name: t\ncar: wr8\nsteps: [connect]\n"
                      "client: {reference: {settings: {auth: WRONG-AUTH, auth_timeout: 1s}}}\n")
                    .client)
                .settings,
            (nlohmann::json{{"auth", "WRONG-AUTH"}, {"auth_timeout", "1s"}}));

  const auto error = [](const std::string& car, const std::string& settings) {
    return error_of("name: t\ncar: " + car + "\nsteps: [" +
                    (car == "arduino" ? "PING" : "connect") +
                    "]\nclient: {reference: {settings: " + settings + "}}\n");
  };
  /// A car, the settings its reference client is given, and the error.
  struct SettingsCase {
    std::string car;
    std::string settings;
    std::string error;
  };
  const std::vector<SettingsCase> cases = {
      {"logi", "{max_retrys: 1}",
       "t.yaml:4:33: 'client: reference: settings' (LOGI): unknown key 'max_retrys' "
       "(allowed: feedback_timeout, max_retries, reconnect_delays, stale_after, keepalive, "
       "keepalive_period); did you mean 'max_retries'?"},
      {"logi", "{max_retries: 11}",
       "t.yaml:4:46: 'client: reference: settings': 'max_retries' must be a whole number "
       "0..10, got '11'"},
      {"logi", "{feedback_timeout: 800}",
       "t.yaml:4:51: 'client: reference: settings': 'feedback_timeout' must be a duration "
       "above 0 with a unit (800ms, 2s), got '800'"},
      {"logi", "{reconnect_delays: []}",
       "t.yaml:4:51: 'client: reference: settings': 'reconnect_delays' must be a list of "
       "durations above 0, like [1s, 2s, 3s], got '[]'"},
      {"wr8", "{auth: SHORT}",
       "t.yaml:4:39: 'client: reference: settings': 'auth' must be a text of exactly 10 "
       "printable characters, got 'SHORT'"},
      {"arduino", "{keepalive: true}",
       "t.yaml:4:33: 'client: reference: settings' (Arduino): unknown key 'keepalive' "
       "(allowed: base_timeout, max_retries, max_bad_cs_resends, health_check_interval, "
       "reconnect_base_delay, max_reconnect_attempts, reconnect_ping_retries)"},
      // Zero is "never" where the library says so, and refused elsewhere.
      {"arduino", "{health_check_interval: 0s}", ""},
      {"leka", "{info_timeout: 0s}",
       "t.yaml:4:47: 'client: reference: settings': 'info_timeout' must be a duration above "
       "0 with a unit (800ms, 2s), got '0s'"},
      {"leka", "max_retries",
       "t.yaml:4:32: 'client: reference: settings' must be a map like {max_retries: 0}"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.car + ": " + c.settings);
    EXPECT_EQ(error(c.car, c.settings), c.error);
  }
}

TEST(ScenarioYaml, FilesAreFoundRelativeToTheScenario) {
  const auto s = load_scenario(kData + "/relative.yaml");
  EXPECT_EQ(s.world, kData + "/worlds/corridor.yaml");
  ASSERT_EQ(s.faults.rules.size(), 1u);
  EXPECT_EQ(s.faults.rules[0].name, "");
  ASSERT_EQ(s.steps.size(), 3u);
  EXPECT_EQ(std::get<FaultsStep>(s.steps[1].action).profile, s.faults);
  EXPECT_EQ(std::get<FaultsStep>(s.steps[2].action).profile, link::FaultProfile{});
  EXPECT_EQ(s.steps[2].text, "faults off");

  const auto up = load_scenario(kData + "/nested/up.yaml");
  EXPECT_EQ(up.world, kData + "/worlds/corridor.yaml");
  EXPECT_EQ(up.faults, s.faults);
}

TEST(ScenarioYaml, AMissingFileIsReportedWhereItIsNamed) {
  EXPECT_EQ(error_of("name: t\ncar: logi\nworld: worlds/nowhere.yaml\nsteps: [connect]\n"),
            "t.yaml:3:8: world file 'worlds/nowhere.yaml' does not exist (looked for "
            "worlds/nowhere.yaml)");
  try {
    load_scenario(kData + "/nested/../relative.yaml");
  } catch (const config::ConfigError& e) {
    FAIL() << e.what();
  }
  const std::string yaml = "name: t\ncar: logi\nsteps:\n  - faults: {file: gone.yaml}\n";
  try {
    parse_scenario_text(yaml, kData + "/x.yaml");
    FAIL() << "loaded";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.line(), 4);
    EXPECT_EQ(e.column(), 20);
    EXPECT_EQ(std::string(e.what()), kData +
                                         "/x.yaml:4:20: fault profile file 'gone.yaml' does not "
                                         "exist (looked for " +
                                         kData + "/gone.yaml)");
  }
}

TEST(ScenarioYaml, AFaultFileErrorKeepsItsOwnPosition) {
  try {
    load_scenario(kData + "/broken-faults.yaml");
    FAIL() << "loaded";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.file(), kData + "/faults/broken.yaml");
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.column(), 5);
    EXPECT_NE(std::string(e.what()).find("unknown key 'frist'"), std::string::npos) << e.what();
  }
}

TEST(ScenarioYaml, InlineFaultErrorsPointIntoTheScenario) {
  try {
    parse("name: t\ncar: logi\nsteps: [connect]\nfaults:\n  - kind: drop\n    frist: 1\n");
    FAIL() << "loaded";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.file(), "t.yaml");
    EXPECT_EQ(e.line(), 6);
    EXPECT_EQ(e.column(), 5);
  }
}

TEST(ScenarioYaml, AFileThatCannotBeReadIsAnErrorWithoutPosition) {
  try {
    load_scenario(kData + "/no-such-scenario.yaml");
    FAIL() << "loaded";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(
        std::string(e.what()),
        kData + "/no-such-scenario.yaml: cannot read the scenario file: No such file or directory");
  }
}

// --------------------------------------------------------------------- steps

TEST(ScenarioYamlSteps, EveryKindOfStep) {
  const auto s = parse(
      "name: t\n"
      "car: logi\n"
      "steps:\n"
      "  - connect\n"                              // 4
      "  - do: \"speed 50\"\n"                     // 5
      "  - wait: 1500ms\n"                         // 6
      "  - wait_until: {client: connected}\n"      // 7
      "    timeout: 5s\n"                          // 8
      "  - wait_until: {received: \"MV:STOP\"}\n"  // 9
      "  - car: {close: reset}\n"                  // 10
      "  - faults: off\n"                          // 11
      "  - obstacle: {ahead: 30cm}\n"              // 12
      "  - obstacle: {ahead: 0.5, name: box}\n"    // 13
      "  - obstacle: remove\n"                     // 14
      "  - obstacle: {remove: box}\n");            // 15
  ASSERT_EQ(s.steps.size(), 11u);
  EXPECT_EQ(s.steps[0], step_of(4, "connect", ActionStep{"connect"}));
  EXPECT_EQ(s.steps[1], step_of(5, "speed 50", ActionStep{"speed 50"}));
  EXPECT_EQ(s.steps[2], step_of(6, "wait 1500ms", WaitStep{milliseconds(1500)}));
  const auto& until = std::get<WaitUntilStep>(s.steps[3].action);
  EXPECT_EQ(until.until, (Matcher{Source::client,
                                  ClientKind::connection,
                                  {{"state", Op::equals, "connected"}},
                                  "client connected"}));
  EXPECT_EQ(until.timeout, seconds(5));
  EXPECT_EQ(s.steps[3].text, "wait until {client: connected}");
  const auto& until2 = std::get<WaitUntilStep>(s.steps[4].action);
  EXPECT_EQ(until2.until, car_received("MV:STOP"));
  EXPECT_EQ(until2.timeout, seconds(10));
  const auto& car = std::get<CarStep>(s.steps[5].action);
  EXPECT_EQ(car.behaviour.action, mocks::Action{mocks::CloseConnection{link::CloseMode::reset}});
  EXPECT_EQ(car.behaviour.when, mocks::When{});
  EXPECT_EQ(s.steps[5].text, "car {close: reset}");
  EXPECT_EQ(std::get<FaultsStep>(s.steps[6].action).profile, link::FaultProfile{});
  EXPECT_EQ(std::get<ObstacleStep>(s.steps[7].action), (ObstacleStep{true, 0.3, "obstacle"}));
  EXPECT_EQ(std::get<ObstacleStep>(s.steps[8].action), (ObstacleStep{true, 0.5, "box"}));
  EXPECT_EQ(std::get<ObstacleStep>(s.steps[9].action), (ObstacleStep{false, 0.3, "obstacle"}));
  EXPECT_EQ(std::get<ObstacleStep>(s.steps[10].action), (ObstacleStep{false, 0.3, "box"}));
}

mocks::Behaviour car_step(const std::string& value) {
  const auto s = parse("name: t\ncar: logi\nsteps:\n  - car: " + value + "\n");
  return std::get<CarStep>(s.steps.at(0).action).behaviour;
}

TEST(ScenarioYamlSteps, CarBehavioursInShortAndFullForm) {
  EXPECT_EQ(car_step("{mute_telemetry: 3s}").action,
            mocks::Action{mocks::MuteTelemetry{seconds(3)}});
  EXPECT_EQ(car_step("{reject: MV}").action, mocks::Action{(mocks::Reject{"MV", 1})});
  EXPECT_EQ(car_step("{reject: {match: SP, times: 2}}").action,
            mocks::Action{(mocks::Reject{"SP", 2})});
  EXPECT_EQ(car_step("{ignore: {match: ST, for: 2s}}").action,
            mocks::Action{(mocks::Ignore{"ST", std::nullopt, seconds(2)})});
  EXPECT_EQ(car_step("{send: \"LOGI:FB:SP:1:00#\"}").action,
            mocks::Action{(mocks::SendBytes{protocol::Bytes{
                'L', 'O', 'G', 'I', ':', 'F', 'B', ':', 'S', 'P', ':', '1', ':', '0', '0', '#'}})});
  EXPECT_EQ(car_step("{send_hex: \"2A 2B\"}").action,
            mocks::Action{(mocks::SendBytes{protocol::Bytes{0x2A, 0x2B}})});
  EXPECT_EQ(car_step("fault").action, mocks::Action{mocks::EnterFault{}});
  EXPECT_EQ(car_step("clear_fault").action, mocks::Action{mocks::ClearFault{}});
  EXPECT_EQ(car_step("close").action, mocks::Action{mocks::CloseConnection{}});
  // The full form of docs/mocks.md, with its own trigger.
  const auto full =
      car_step("{do: reject, match: MV, times: 2, after: \"ST:RUN\", name: no-moves}");
  EXPECT_EQ(full.name, "no-moves");
  EXPECT_EQ(full.when.after_frame, "ST:RUN");
  EXPECT_EQ(full.action, mocks::Action{(mocks::Reject{"MV", 2})});
  // A short form that says when.
  const auto later = car_step("{close: graceful, at: 8s}");
  EXPECT_EQ(later.when.at, seconds(8));
}

TEST(ScenarioYamlSteps, ActionsAreCheckedByEachCarsParser) {
  // The vocabulary docs/scenarios.md shows for each car.
  EXPECT_NO_THROW(
      parse("name: t\ncar: logi\nsteps: [connect, mode MAN, speed 50, press FWD, "
            "release, station 2, run, stop, estop, wait 1s, confirm, disconnect]\n"));
  EXPECT_NO_THROW(
      parse("name: t\ncar: wr8\nsteps: [connect, drive 30, turn -10, task blink, "
            "get-settings, \"set p=1.5\", wait-data, disconnect]\n"));
  EXPECT_NO_THROW(
      parse("name: t\ncar: arduino\nsteps: [PING, V 160, M 30, R -90, S, STATUS, "
            "reconnect, wait 500ms]\n"));
  EXPECT_NO_THROW(
      parse("name: t\ncar: leka\nsteps: [motor all forward 120, belt all 0 0 255, "
            "info, wait 1s]\n"));
  EXPECT_EQ(error_of("name: t\ncar: wr8\nsteps:\n  - drive fast\n"),
            "t.yaml:4:11: step 1: WR8 action 'drive fast': expected a distance in cm (a whole "
            "number), got 'fast'");
  EXPECT_EQ(error_of("name: t\ncar: arduino\nsteps:\n  - quit\n"),
            "t.yaml:4:5: step 1: Arduino action 'quit': 'quit' is a command of the interactive "
            "prompt, not an operator action");
}

TEST(ScenarioYamlSteps, AnyStepCanBeExpectedToFailWithAReasonItMustGive) {
  const auto s = parse(
      "name: t\n"
      "car: logi\n"
      "steps:\n"
      "  - connect\n"
      "  - {do: \"press FWD\", expect: fail}\n"
      "  - do: \"press BWD\"\n"
      "    expect: {fail: \"Not in manual mode\"}\n"
      "  - wait_until: {client: stale}\n"
      "    timeout: 1s\n"
      "    expect: fail\n"
      "  - {wait: 1s, expect: {fail: }}\n"
      "schedule:\n"
      "  - {at: 2s, do: run, expect: fail}\n");
  ASSERT_EQ(s.steps.size(), 5u);
  EXPECT_FALSE(s.steps[0].expect_failure);
  EXPECT_TRUE(s.steps[1].expect_failure);
  EXPECT_EQ(s.steps[1].failure_contains, "");
  EXPECT_EQ(s.steps[1].text, "press FWD");  // step matchers still find it by its text
  EXPECT_TRUE(s.steps[2].expect_failure);
  EXPECT_EQ(s.steps[2].failure_contains, "Not in manual mode");
  EXPECT_TRUE(s.steps[3].expect_failure);
  EXPECT_EQ(std::get<WaitUntilStep>(s.steps[3].action).timeout, seconds(1));
  EXPECT_TRUE(s.steps[4].expect_failure);
  EXPECT_EQ(s.steps[4].failure_contains, "");
  ASSERT_EQ(s.schedule.size(), 1u);
  EXPECT_TRUE(s.schedule[0].step.expect_failure);

  const std::string head = "name: t\ncar: logi\nsteps:\n  - ";
  expect_errors({
      {head + "{do: \"press FWD\", expect: fial}\n",
       "t.yaml:4:31: step 1: 'expect' must be fail or {fail: \"words the reason contains\"}, "
       "got 'fial'; did you mean 'fail'?"},
      {head + "{do: \"press FWD\", expect: {fails: x}}\n",
       "t.yaml:4:32: step 1: 'expect': unknown key 'fails' (allowed: fail); did you mean "
       "'fail'?"},
      {head + "{do: \"press FWD\", expect: {fail: [a, b]}}\n",
       "t.yaml:4:38: step 1: 'expect': 'fail' must be a text or a number, not a list"},
  });
}

TEST(ScenarioYamlSteps, ScheduleAtATimeOrOnAnEvent) {
  const auto s = logi(
      "schedule:\n"
      "  - at: 5s\n"
      "    car: {close: reset}\n"
      "  - when: {wire: {received: \"ST:RUN\"}}\n"
      "    occurrence: 2\n"
      "    offset: 100ms\n"
      "    car: {mute_telemetry: 3s}\n"
      "  - when: {step: release, at: start, offset: -50ms}\n"
      "    do: estop\n"
      "  - when: {client: stale, occurrence: last}\n"
      "    obstacle: remove\n");
  ASSERT_EQ(s.schedule.size(), 4u);
  EXPECT_EQ(s.schedule[0].when, (Anchor{std::nullopt, 1, seconds(5)}));
  EXPECT_EQ(s.schedule[0].step.line, 13);
  EXPECT_EQ(s.schedule[1].when, (Anchor{car_received("ST:RUN"), 2, milliseconds(100)}));
  EXPECT_EQ(std::get<CarStep>(s.schedule[1].step.action).behaviour.action,
            mocks::Action{mocks::MuteTelemetry{seconds(3)}});
  EXPECT_EQ(s.schedule[2].when.event, (Matcher{Source::step,
                                               StepKind::start,
                                               {{"text", Op::equals, "release"}},
                                               "step 'release' started"}));
  EXPECT_EQ(s.schedule[2].when.offset, milliseconds(-50));
  EXPECT_EQ(s.schedule[2].step, step_of(19, "estop", ActionStep{"estop"}));
  EXPECT_EQ(s.schedule[3].when.occurrence, -1);
  EXPECT_EQ(s.schedule[3].when.event->kind, ClientKind::stale);
}

// ----------------------------------------------------------------- variables

TEST(ScenarioYamlVariables, SubstitutedEverywhereAndOverridden) {
  const auto s = load_scenario(kData + "/overrides.yaml");
  EXPECT_EQ(s.name, "speed-50");
  EXPECT_EQ(s.steps.at(2).text, "speed 50");
  EXPECT_EQ(s.variables, (std::map<std::string, std::string>{{"mode", "MAN"}, {"speed", "50"}}));
  const auto o = load_scenario(kData + "/overrides.yaml", {{"speed", "80"}});
  EXPECT_EQ(o.name, "speed-80");
  EXPECT_EQ(o.steps.at(2).text, "speed 80");
  EXPECT_EQ(o.variables.at("speed"), "80");
  // An override's value is checked like the file's own.
  try {
    load_scenario(kData + "/overrides.yaml", {{"speed", "fast"}});
    FAIL() << "loaded";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.line(), 9);
    EXPECT_NE(std::string(e.what()).find("step 3: LOGI action 'speed fast'"), std::string::npos)
        << e.what();
  }
}

TEST(ScenarioYamlVariables, UndefinedVariableIsAnErrorAtItsPosition) {
  EXPECT_EQ(error_of("name: t\ncar: logi\nvariables: {speed: 50}\nsteps:\n  - \"speed ${sped}\"\n"),
            "t.yaml:5:12: variable 'sped' is not defined (defined: speed); did you mean 'speed'?");
  EXPECT_EQ(error_of("name: t\ncar: logi\nsteps:\n  - speed ${x}\n"),
            "t.yaml:4:11: variable 'x' is not defined (the scenario has no 'variables')");
  // $${ is a literal ${, for shell commands of an external client.
  const auto s =
      parse("name: t\ncar: logi\nsteps: [connect]\nclient: {exec: \"run $${HOME}/c {port}\"}\n");
  EXPECT_EQ(std::get<ExecClient>(s.client).command, "run ${HOME}/c {port}");
}

TEST(ScenarioYamlProfiles, AReplyLatencyIsADurationAndNoneIsZero) {
  EXPECT_EQ(parse("name: t\ncar: arduino\nreply_latency: 20ms\nsteps: [PING]\n").reply_latency,
            link::milliseconds(20));
  EXPECT_EQ(parse("name: t\ncar: arduino\nsteps: [PING]\n").reply_latency, std::nullopt);
  EXPECT_EQ(error_of("name: t\ncar: arduino\nreply_latency: 20\nsteps: [PING]\n"),
            "t.yaml:3:16: 'reply_latency' must be a duration with a unit (500ms, 2s, 1.5s), got "
            "'20'");
}

TEST(ScenarioYamlProfiles, TheCarsProfileIsReadAndAWrongOneNamesTheValidOnes) {
  EXPECT_EQ(parse("name: t\ncar: arduino\nprofile: readme\nsteps: [PING]\n").profile, "readme");
  EXPECT_EQ(parse("name: t\ncar: leka\nprofile: comspecs-v3\nsteps: [wait: 1s]\n").profile,
            "comspecs-v3");
  EXPECT_EQ(parse("name: t\ncar: arduino\nsteps: [PING]\n").profile, "")
      << "no key: the car's default profile";
  EXPECT_EQ(error_of("name: t\ncar: arduino\nprofile: sketch\nsteps: [PING]\n"),
            "t.yaml:3:10: 'profile': arduino has no profile 'sketch'; its profiles are firmware "
            "(the default) and readme");
  // A profile of another car is as wrong as a made-up one.
  EXPECT_EQ(error_of("name: t\ncar: logi\nprofile: comspecs-v3\nsteps: [connect]\n"),
            "t.yaml:3:10: 'profile': logi has no profile 'comspecs-v3'; its profiles are guide "
            "(the default) and firmware");
}

TEST(ScenarioYamlProfiles, AWr8ProgramProfileChecksActionsAndSettingsByItsOwnWords) {
  EXPECT_EQ(
      parse("name: t\ncar: wr8\nprofile: svgui-head\nsteps: [connect, control 0 0.5]\n").profile,
      "svgui-head");
  // The document's words are not the real programs'.
  const std::string drive =
      error_of("name: t\ncar: wr8\nprofile: svgui-2019\nsteps: [connect, drive 30]\n");
  EXPECT_NE(drive.find("t.yaml:4:18: step 2: WR8 action 'drive 30': "), std::string::npos) << drive;
  EXPECT_NE(drive.find("forward"), std::string::npos) << drive;
  // Nor is a head word a v2019 one.
  EXPECT_NE(
      error_of("name: t\ncar: wr8\nprofile: svgui-2019\nsteps: [control 0 1]\n").find("svgui-head"),
      std::string::npos);
  // The client's settings are the real-program client's.
  EXPECT_EQ(parse("name: t\ncar: wr8\nprofile: svgui-2019\nclient: {reference: {settings: "
                  "{wait_for_login: false, login_timeout: 5s}}}\nsteps: [connect]\n")
                .profile,
            "svgui-2019");
  const std::string auth = error_of(
      "name: t\ncar: wr8\nprofile: svgui-head\nclient: {reference: {settings: {auth: "
      "HIL-WR8-01}}}\nsteps: [connect]\n");
  EXPECT_NE(auth.find("login_timeout"), std::string::npos) << auth;
}

// -------------------------------------------------------------------- errors

TEST(ScenarioYamlErrors, EveryMistakeNamesItsLineAndColumn) {
  expect_errors({
      // Unknown key, with the allowed ones and the likely one.
      {"name: t\ncar: logi\nstpes: [connect]\n",
       "t.yaml:3:1: the scenario: unknown key 'stpes' (allowed: name, description, tags, "
       "car, profile, reply_latency, world, seed, timeout, settle, at_end, variables, faults, "
       "client, setup, steps, teardown, schedule, expect); did you mean 'steps'?"},
      {"name: t\ncar: logi\nsteps: [connect]\nat_end: movin\n",
       "t.yaml:4:9: 'at_end' must be at_rest, moving or any, got 'movin'; did you mean "
       "'moving'?"},
      {"name: t\ncar: logi\nsteps: [connect]\nat_end: [moving]\n",
       "t.yaml:4:9: 'at_end' must be a text or a number, not a list"},
      {"name: t\ncar: logi\n", "t.yaml:1:1: the scenario: 'steps' is missing"},
      {"name: t\ncar: tesla\nsteps: [connect]\n",
       "t.yaml:2:6: unknown car 'tesla' (expected logi, wr8, arduino or leka)"},
      {"name: t\ncar: logi\ntimeout: 60\nsteps: [connect]\n",
       "t.yaml:3:10: 'timeout' must be a duration with a unit (500ms, 2s, 1.5s), got '60'"},
      {"name: t\ncar: logi\ntags: logi\nsteps: [connect]\n",
       "t.yaml:3:7: 'tags' must be a list of words, like [logi, safety]"},
      {"name: t\ncar: logi\nsteps:\n  - speed 50\n  - pres FWD\n",
       "t.yaml:5:5: step 2: LOGI action 'pres FWD': unknown action 'pres' (expected one of "
       "connect, disconnect, speed, mode, press, release, station, run, stop, estop, wait, "
       "confirm)"},
      // The parser's column inside a quoted string.
      {"name: t\ncar: logi\nsteps:\n  - do: \"speed 500\"\n",
       "t.yaml:4:16: step 1: LOGI action 'speed 500': expected a speed 0..100, got '500'"},
      {"name: t\ncar: logi\nsteps:\n  - wait: 5\n",
       "t.yaml:4:11: step 1: 'wait' must be a duration with a unit (500ms, 2s, 1.5s), got '5'"},
      {"name: t\ncar: logi\nsteps:\n  - {wait: 1s, car: fault}\n",
       "t.yaml:4:21: step 1: a step does one thing: 'wait' and 'car' are two steps"},
      {"name: t\ncar: logi\nsteps:\n  - car: {mute_telemetry: soon}\n",
       "t.yaml:4:27: step 1: car behaviour (mute-telemetry): 'for' must be a duration with a "
       "unit, like 250ms or 1.5s (units: ns, us, ms, s)"},
      {"name: t\ncar: logi\nsteps:\n  - car: {rejct: MV}\n",
       "t.yaml:4:11: step 1: unknown key 'rejct' (allowed: reject, ignore, "
       "mute_telemetry, send, send_hex, fault, clear_fault, close, at, after, after_count, "
       "name, do); did you mean 'reject'?"},
      {"name: t\ncar: logi\nsteps: [connect]\nexpect:\n  - {received: SP, within: 1s, "
       "after: relase}\n",
       "t.yaml:5:39: expectation 1: 'after': no step reads 'relase' (steps: connect)"},
      {"name: t\ncar: logi\nsteps: [connect, release]\nexpect:\n  - {received: SP, "
       "after: {step: relase}}\n",
       "t.yaml:5:34: expectation 1: 'after': 'step': no step reads 'relase' (steps: connect, "
       "release); did you mean 'release'?"},
      {"name: t\ncar: logi\nsteps: [connect]\nexpect:\n  - {client: conected}\n",
       "t.yaml:5:14: expectation 1: 'client': unknown client state 'conected' (expected "
       "connected, disconnected, connecting, authenticating, reconnecting, degraded, down, stale, "
       "fresh, parse_error); did you mean 'connected'?"},
      {"name: t\ncar: logi\nsteps: [connect]\nexpect:\n  - {received: SP, count: 1, "
       "never: true}\n",
       "t.yaml:5:27: expectation 1: 'never' and 'count' do not go together"},
      {"name: t\ncar: logi\nsteps: [connect]\nexpect:\n  - {within: 1s}\n",
       "t.yaml:5:5: expectation 1: nothing to match: give one of wire, client, sim, step, "
       "fault, car (or received, sent_by_client, sent_by_car, received_by_client)"},
      {"name: t\ncar: logi\nsteps: [connect]\nexpect:\n  - {received: SP, "
       "tolerance: 1s}\n",
       "t.yaml:5:31: expectation 1: 'tolerance' goes with 'times'"},
      {"name: t\ncar: logi\nsteps: [connect]\nclient: {exec: \"c {hots}\"}\n",
       "t.yaml:4:19: unknown placeholder '{hots}' (known: {host}, {port}, {endpoint}, {pty}, "
       "{actions}, {scenario}); did you mean '{host}'?"},
      {"name: t\ncar: logi\nsteps: [connect]\nschedule:\n  - car: fault\n",
       "t.yaml:5:5: schedule 1: 'at' (a run time like 5s) or 'when' (a matcher) is missing"},
      {"name: t\ncar: logi\nname: u\nsteps: [connect]\n",
       "t.yaml:3:1: the scenario: key 'name' is given twice"},
  });
}

TEST(ScenarioYamlErrors, YamlSyntaxErrorsKeepTheParsersPosition) {
  expect_errors({
      {"name: t\ncar: logi\nsteps: [connect\n",
       "t.yaml:4:1: not valid YAML: end of sequence flow not found"},
      {"- just\n- a list\n",
       "t.yaml:1:1: a scenario is a map with at least 'name', 'car' and 'steps' (see "
       "docs/scenarios.md)"},
  });
}

// ----------------------------------------------------------- shipped files

TEST(ScenarioYamlExamples, EveryExampleScenarioLoads) {
  const std::filesystem::path dir = std::string(HIL_SOURCE_DIR) + "/scenarios/examples";
  std::size_t loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    try {
      const auto s = load_scenario(entry.path().string());
      EXPECT_FALSE(s.steps.empty());
      EXPECT_FALSE(s.expectations.empty());
      ++loaded;
    } catch (const config::ConfigError& e) {
      ADD_FAILURE() << e.what();
    }
  }
  EXPECT_GE(loaded, 4u);
}

}  // namespace
}  // namespace hil::harness
