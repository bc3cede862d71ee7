#pragma once
// Scenario pieces built in code for the runner's tests, and ways to read
// a run's timeline back.

#include <string>
#include <utility>
#include <vector>

#include "harness/outcome.hpp"
#include "harness/scenario.hpp"

namespace hil::harness::test {

/// A step as a scenario file would give it (line 0: built in code).
inline Step step_of(std::string text, StepAction action) {
  Step s;
  s.text = std::move(text);
  s.action = std::move(action);
  return s;
}

inline Step action(const std::string& text) {
  return step_of(text, ActionStep{text});
}

inline Step wait(Duration d) {
  return step_of("wait", WaitStep{d});
}

/// The records of one kind, in time order.
inline std::vector<Record> of(const ScenarioOutcome& o, RecordKind kind) {
  std::vector<Record> out;
  for (const auto& r : o.timeline.records())
    if (r.kind == kind) out.push_back(r);
  return out;
}

}  // namespace hil::harness::test
