#pragma once
// What the scenario loader's tests share: scenario texts read as "t.yaml",
// the error a text raises, and the matchers the loader builds for QA's
// shorthand.

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "harness/scenario_yaml.hpp"

namespace hil::harness::test {

using link::milliseconds;
using link::seconds;
using Op = FieldTest::Op;

inline const std::string kData = std::string(HIL_SOURCE_DIR) + "/tests/harness/data/scenario_yaml";

inline Scenario parse(const std::string& yaml) {
  return parse_scenario_text(yaml, "t.yaml");
}

/// A LOGI scenario with the usual steps, then `tail` (expectations and so on).
inline Scenario logi(const std::string& tail) {
  return parse(
      "name: t\n"
      "car: logi\n"
      "steps:\n"
      "  - connect\n"
      "  - mode MAN\n"
      "  - speed 50\n"
      "  - press FWD\n"
      "  - release\n"
      "  - station 2\n"
      "  - run\n"
      "  - estop\n" +
      tail);
}

/// The message of the error `yaml` raises, or "" when it loads.
inline std::string error_of(const std::string& yaml,
                            const std::map<std::string, std::string>& overrides = {}) {
  try {
    parse_scenario_text(yaml, "t.yaml", overrides);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

/// A scenario text and the error loading it as "t.yaml" raises ("": it loads).
struct ErrorCase {
  std::string yaml;
  std::string error;
};

/// Expects each case's error, traced by its text.
inline void expect_errors(const std::vector<ErrorCase>& cases) {
  for (const auto& c : cases) {
    SCOPED_TRACE(c.yaml);
    EXPECT_EQ(error_of(c.yaml), c.error);
  }
}

/// A step that must succeed, as the loader makes it.
inline Step step_of(int line, std::string text, StepAction action) {
  Step s;
  s.line = line;
  s.text = std::move(text);
  s.action = std::move(action);
  return s;
}

inline Matcher car_received(const std::string& frame) {
  return Matcher{Source::wire,
                 WireKind::frame,
                 {{"dir", Op::equals, "to_car"},
                  {"stage", Op::equals, "delivered"},
                  {"frame", Op::kind_prefix, frame}},
                 "car received " + frame};
}

inline Matcher step_ended(const std::string& text) {
  return Matcher{
      Source::step, StepKind::end, {{"text", Op::equals, text}}, "step '" + text + "' ended"};
}

inline Matcher step_started(const std::string& text) {
  return Matcher{
      Source::step, StepKind::start, {{"text", Op::equals, text}}, "step '" + text + "' started"};
}

}  // namespace hil::harness::test
