// The matchers, windows and quantifiers of a scenario's expectations as
// QA writes them, and what the loader makes of each.

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "harness/scenario_yaml.hpp"
#include "tests/harness/scenario_yaml_support.hpp"

namespace hil::harness {
namespace {

using namespace test;

// ------------------------------------------------------------------ matchers

/// What the loader makes of `{client: ...}`: the client's records of
/// `kind` that pass `tests`, named `text` in reports.
Matcher client_matcher(RecordKind kind, std::vector<FieldTest> tests, std::string text) {
  return Matcher{Source::client, kind, std::move(tests), std::move(text)};
}

Matcher matcher_of(const std::string& expectation) {
  return logi("expect:\n  - " + expectation + "\n").expectations.at(0).what;
}

TEST(ScenarioYamlMatchers, WireDirectionsAndStages) {
  EXPECT_EQ(matcher_of("{wire: {received: \"MV:STOP\"}}"), car_received("MV:STOP"));
  const auto sent = matcher_of("{wire: {sent_by_client: SP}}");
  EXPECT_EQ(sent.tests, (std::vector<FieldTest>{{"dir", Op::equals, "to_car"},
                                                {"stage", Op::equals, "sent"},
                                                {"frame", Op::kind_prefix, "SP"}}));
  const auto car_sent = matcher_of("{sent_by_car: STAT}");
  EXPECT_EQ(car_sent.tests, (std::vector<FieldTest>{{"dir", Op::equals, "to_client"},
                                                    {"stage", Op::equals, "sent"},
                                                    {"frame", Op::kind_prefix, "STAT"}}));
  const auto got = matcher_of("{received_by_client: \"FB:MV\", valid: true}");
  EXPECT_EQ(got.tests, (std::vector<FieldTest>{{"dir", Op::equals, "to_client"},
                                               {"stage", Op::equals, "delivered"},
                                               {"frame", Op::kind_prefix, "FB:MV"},
                                               {"valid", Op::equals, true}}));
  EXPECT_EQ(matcher_of("{wire: close}"),
            (Matcher{Source::wire, WireKind::close, {}, "link closed"}));
}

TEST(ScenarioYamlMatchers, FrameContentTextHexMessageAndFields) {
  const auto sp = matcher_of("{received: SP, text: {contains: \"SP:050\"}}");
  EXPECT_EQ(sp.tests.back(), (FieldTest{"text", Op::contains, "SP:050"}));
  EXPECT_EQ(sp.text, "car received SP with text containing 'SP:050'");
  EXPECT_EQ(matcher_of("{received: SP, text: \"LOGI:SP:050:D7#\"}").tests.back(),
            (FieldTest{"text", Op::equals, "LOGI:SP:050:D7#"}));
  // Hex in any spacing and case is written as the timeline writes bytes.
  EXPECT_EQ(matcher_of("{sent_by_car: STAT, hex: \"4c4f 47\"}").tests.back(),
            (FieldTest{"hex", Op::equals, "4C 4F 47"}));
  EXPECT_EQ(matcher_of("{sent_by_car: STAT, hex: {contains: 4c4f}}").tests.back(),
            (FieldTest{"hex", Op::contains, "4C 4F"}));
  const auto nack = matcher_of("{received_by_client: \"FB:MV\", message: rejected}");
  EXPECT_EQ(nack.tests.back(), (FieldTest{"message", Op::contains, "rejected"}));
  EXPECT_EQ(nack.text, "client received FB:MV with message containing 'rejected'");

  const auto stat = matcher_of(
      "{received_by_client: STAT, fields: {speed_percent: 50, mode: MAN, track: 0110, "
      "distance_cm: {at_least: 10, below: 300}, manual: {not: FWD}, rpm: {contains: \"0:0\"}}}");
  EXPECT_EQ(stat.tests, (std::vector<FieldTest>{{"dir", Op::equals, "to_client"},
                                                {"stage", Op::equals, "delivered"},
                                                {"frame", Op::kind_prefix, "STAT"},
                                                {"fields.speed_percent", Op::equals, 50},
                                                {"fields.mode", Op::equals, "MAN"},
                                                {"fields.track", Op::equals, "0110"},
                                                {"fields.distance_cm", Op::greater_equal, 10.0},
                                                {"fields.distance_cm", Op::less, 300.0},
                                                {"fields.manual", Op::not_equals, "FWD"},
                                                {"fields.rpm", Op::contains, "0:0"}}));
  EXPECT_EQ(stat.text,
            "client received STAT with speed_percent = 50, mode = MAN, track = 0110, distance_cm "
            ">= 10 < 300, manual not FWD, rpm containing '0:0'");
  // The same keys in every place a matcher goes.
  const auto s = logi(
      "schedule:\n"
      "  - when: {received: SP, fields: {percent: 50}}\n"
      "    car: fault\n"
      "expect:\n"
      "  - never: {received: SP, text: {contains: \"SP:100\"}}\n"
      "  - wire: {received: MD, message: MAN}\n"
      "    after: {received: SP, hex: {contains: 4C}}\n");
  EXPECT_EQ(s.schedule[0].when.event->tests.back(), (FieldTest{"fields.percent", Op::equals, 50}));
  EXPECT_EQ(s.expectations[0].quantifier, Quantifier::never);
  EXPECT_EQ(s.expectations[1].window.from.event->tests.back(),
            (FieldTest{"hex", Op::contains, "4C"}));
}

TEST(ScenarioYamlMatchers, InvalidFramesOfAKindIncludeThoseTheDecoderNamedOnlyInPart) {
  EXPECT_EQ(matcher_of("{received_by_client: \"FB:SP\", valid: false}").tests,
            (std::vector<FieldTest>{{"dir", Op::equals, "to_client"},
                                    {"stage", Op::equals, "delivered"},
                                    {"frame", Op::kind_either_prefix, "FB:SP"},
                                    {"valid", Op::equals, false}}));
  EXPECT_EQ(matcher_of("{received_by_client: \"FB:SP\", valid: true}").tests[2],
            (FieldTest{"frame", Op::kind_prefix, "FB:SP"}));
  EXPECT_EQ(matcher_of("{received_by_client: \"FB:SP\"}").tests[2],
            (FieldTest{"frame", Op::kind_prefix, "FB:SP"}));
}

TEST(ScenarioYamlMatchers, FrameContentMistakesAreReportedWhereTheyAre) {
  const std::string head = "name: t\ncar: logi\nsteps: [connect]\nexpect:\n  - ";
  expect_errors({
      {head + "{received: SP, text: {contans: x}}\n",
       "t.yaml:5:27: expectation 1: 'text': unknown key 'contans' (allowed: contains); did "
       "you mean 'contains'?"},
      {head + "{received: SP, hex: \"4C4\"}\n",
       "t.yaml:5:25: expectation 1: 'hex' must be whole bytes (two hex digits each)"},
      {head + "{received: SP, hex: \"LOGI\"}\n",
       "t.yaml:5:25: expectation 1: 'hex' must be hex digits like \"06 01 FF\", got 'LOGI'"},
      {head + "{received: SP, fields: {precent: 50}}\n",
       "t.yaml:5:29: expectation 1: 'fields': LOGI frames have no field 'precent' (they have "
       "percent, station, speed_percent, running, mode, manual, distance_cm, track, "
       "deviation, obstacle, rpm); did you mean 'percent'?"},
      {head + "{received: SP, fields: {percent: {abve: 50}}}\n",
       "t.yaml:5:39: expectation 1: 'fields': 'percent': unknown key 'abve' (allowed: not, "
       "contains, below, above, at_least, at_most); did you mean 'above'?"},
      {head + "{received: SP, fields: {percent: {above: fast}}}\n",
       "t.yaml:5:46: expectation 1: 'fields': 'percent': 'above' must be a number, got "
       "'fast'"},
      {head + "{received: SP, fields: percent}\n",
       "t.yaml:5:28: expectation 1: 'fields' must be a map of field names to values, like "
       "{percent: 50}"},
      {head + "{client: connected, text: x}\n",
       "t.yaml:5:31: expectation 1: 'text' goes with a wire frame key"},
      // A name far from every known one is a firmware's own key, and is let through.
      {head + "{received_by_client: STAT, fields: {BAT: 87}}\n", ""},
  });
}

TEST(ScenarioYamlMatchers, ClientParseErrorsAndMovementControls) {
  EXPECT_EQ(
      matcher_of("{client: parse_error}"),
      client_matcher(ClientKind::parse_error, {}, "client reported a frame it could not parse"));
  EXPECT_EQ(matcher_of("{client: {parse_error: bad_checksum}}"),
            client_matcher(ClientKind::parse_error, {{"text", Op::contains, "bad_checksum"}},
                           "client could not parse a frame: 'bad_checksum'"));
  EXPECT_EQ(
      matcher_of("{client: {movement: false, reason: not connected}}"),
      client_matcher(ClientKind::movement,
                     {{"enabled", Op::equals, false}, {"reason", Op::contains, "not connected"}},
                     "client disabled movement because of 'not connected'"));
  const std::string head = "name: t\ncar: logi\nsteps: [connect]\nexpect:\n  - client: ";
  EXPECT_NE(error_of(head + "{movement: maybe}\n"), "");
  EXPECT_EQ(error_of(head + "{parse_error: x, state: y}\n"),
            "t.yaml:5:37: expectation 1: 'client': 'state' does not go with 'parse_error'");
}

TEST(ScenarioYamlMatchers, ClientEvents) {
  EXPECT_EQ(matcher_of("{client: stale}"),
            client_matcher(ClientKind::stale, {}, "client warned of stale telemetry"));
  EXPECT_EQ(matcher_of("{client: fresh}").kind, ClientKind::fresh);
  EXPECT_EQ(matcher_of("{client: {login: false, reason: refused}}"),
            client_matcher(ClientKind::login,
                           {{"ok", Op::equals, false}, {"reason", Op::contains, "refused"}},
                           "client login refused because of 'refused'"));
  EXPECT_EQ(matcher_of("{client: {notice: \"Not in manual mode\"}}"),
            client_matcher(ClientKind::notice, {{"text", Op::contains, "Not in manual mode"}},
                           "client notice containing 'Not in manual mode'"));
  EXPECT_EQ(matcher_of("{client: {command: SP, state: rejected}}").tests,
            (std::vector<FieldTest>{{"command", Op::kind_prefix, "SP"},
                                    {"state", Op::equals, "rejected"}}));
  EXPECT_EQ(
      matcher_of("{client: {exit: 0}}"),
      (Matcher{
          Source::client, ClientKind::exit, {{"code", Op::equals, 0}}, "client exited with 0"}));
  EXPECT_EQ(matcher_of("{client: {output: ok}}").tests,
            (std::vector<FieldTest>{{"line", Op::contains, "ok"}}));
  EXPECT_EQ(matcher_of("{client: {action: \"press FWD\", ok: false}}"),
            client_matcher(ClientKind::action,
                           {{"text", Op::equals, "press FWD"}, {"ok", Op::equals, false}},
                           "action 'press FWD' failed"));
  EXPECT_EQ(matcher_of("{client: disconnected}").tests,
            (std::vector<FieldTest>{{"state", Op::equals, "disconnected"}}));
}

TEST(ScenarioYamlMatchers, SimulationEvents) {
  EXPECT_EQ(matcher_of("{sim: moving}").kind, SimKind::moving);
  EXPECT_EQ(matcher_of("{sim: collision}").kind, SimKind::collision);
  EXPECT_EQ(
      matcher_of("{sim: {speed_below: 0.01}}"),
      (Matcher{
          Source::sim, SimKind::sample, {{"speed_mps", Op::less, 0.01}}, "speed below 0.01 m/s"}));
  EXPECT_EQ(matcher_of("{sim: {near: [1.5, 0.4], radius: 0.2}}").tests,
            (std::vector<FieldTest>{{"x_m", Op::greater_equal, 1.3},
                                    {"x_m", Op::less_equal, 1.7},
                                    {"y_m", Op::greater_equal, 0.4 - 0.2},
                                    {"y_m", Op::less_equal, 0.4 + 0.2}}));
}

TEST(ScenarioYamlMatchers, StepsByTheirTextOrItsFirstWords) {
  EXPECT_EQ(matcher_of("{step: release}"), step_ended("release"));
  // "speed" starts exactly one step: "speed 50".
  EXPECT_EQ(matcher_of("{step: speed}"), step_ended("speed 50"));
  EXPECT_EQ(matcher_of("{step: {text: run, at: start}}").kind, StepKind::start);
}

TEST(ScenarioYamlMatchers, FaultAndCarEvents) {
  EXPECT_EQ(matcher_of("{fault: drop}"),
            (Matcher{Source::fault, link::FaultKind::drop, {}, "fault drop"}));
  EXPECT_EQ(matcher_of("{car: fault_state}").tests,
            (std::vector<FieldTest>{{"on", Op::equals, true}}));
  EXPECT_EQ(matcher_of("{car: {behaviour: no-moves}}").tests,
            (std::vector<FieldTest>{{"name", Op::equals, "no-moves"}}));
  // Any fault, and a rule kind that does not exist (it could never match).
  EXPECT_EQ(matcher_of("{fault: \"*\"}").kind, std::nullopt);
  const std::string head = "name: t\ncar: logi\nsteps: [connect]\nexpect:\n  - ";
  expect_errors({
      {head + "{fault: dorp}\n",
       "t.yaml:5:13: expectation 1: 'fault': unknown fault kind 'dorp' (known: fragment, "
       "coalesce, corrupt, drop, duplicate, garbage, delay, stall, bandwidth, disconnect, "
       "reset, refuse, limit_data, slow_close); did you mean 'drop'?"},
      {head + "{fault: {kind: corupt}}\n",
       "t.yaml:5:20: expectation 1: 'fault': 'kind': unknown fault kind 'corupt' (known: "
       "fragment, coalesce, corrupt, drop, duplicate, garbage, delay, stall, bandwidth, "
       "disconnect, reset, refuse, limit_data, slow_close); did you mean 'corrupt'?"},
  });
}

// ------------------------------------------------- windows and quantifiers

Expectation expectation_of(const std::string& body) {
  return logi("expect:\n  - " + body + "\n").expectations.at(0);
}

TEST(ScenarioYamlWindows, FromTheStartAtATimeBetweenAndAfter) {
  EXPECT_EQ(expectation_of("{sim: at_rest, within: 3s}").window, (Window{Anchor{}, seconds(3)}));
  EXPECT_EQ(expectation_of("{sim: at_rest, at: 5s}").window,
            (Window{Anchor{std::nullopt, 1, seconds(5)}, Duration{0}}));
  EXPECT_EQ(expectation_of("{sim: at_rest, at: 5s, within: 1s}").window,
            (Window{Anchor{std::nullopt, 1, seconds(5)}, seconds(1)}));
  EXPECT_EQ(expectation_of("{sim: at_rest, between: [5s, 12s]}").window,
            (Window{Anchor{std::nullopt, 1, seconds(5)}, seconds(7)}));
  EXPECT_EQ(expectation_of("{sim: at_rest, after: 4s}").window,
            (Window{Anchor{std::nullopt, 1, seconds(4)}, std::nullopt}));
  EXPECT_EQ(expectation_of("{sim: at_rest, after: release}").window,
            (Window{Anchor{step_ended("release"), 1, Duration{0}}, std::nullopt}));
  EXPECT_EQ(
      expectation_of("{sim: at_rest, after: {step: release, at: start}}").window.from.event->kind,
      StepKind::start);
  EXPECT_EQ(
      expectation_of("{sim: at_rest, after: {received: \"MV:STOP\", occurrence: 2, offset: 1s}}")
          .window.from,
      (Anchor{car_received("MV:STOP"), 2, seconds(1)}));
}

TEST(ScenarioYamlQuantifiers, EveryQuantifier) {
  EXPECT_EQ(expectation_of("{received: SP, at_least: 2}").quantifier, Quantifier::at_least);
  EXPECT_EQ(expectation_of("{received: SP, at_least: 2}").count, 2u);
  EXPECT_EQ(expectation_of("{received: SP, at_most: 3}").quantifier, Quantifier::at_most);
  EXPECT_EQ(expectation_of("{received: SP, never: true}").quantifier, Quantifier::never);
  EXPECT_EQ(expectation_of("{never: {received: SP}}").what, car_received("SP"));
  const auto only =
      expectation_of("{client: connecting, times: [1s, 3s], tolerance: 100ms, only: true}");
  EXPECT_EQ(only.quantifier, Quantifier::at_times);
  EXPECT_TRUE(only.only);
  const auto always = expectation_of("{always: {sim: {speed_below: 0.5}}, after: release}");
  EXPECT_EQ(always.quantifier, Quantifier::always);
  EXPECT_EQ(always.what.kind, SimKind::sample);
  EXPECT_EQ(always.label, "always: speed below 0.5 m/s after step 'release' ended");
}

}  // namespace
}  // namespace hil::harness
