#pragma once
// Scenario pieces built in code for the runner's tests, and ways to read
// a run's timeline back.

#include <string>
#include <utility>
#include <vector>

#include "harness/outcome.hpp"
#include "harness/scenario.hpp"
#include "link/time.hpp"

namespace hil::harness::test {

using link::milliseconds;
using link::seconds;

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

/// The client's records of `kind` whose `field` equals `value`, named
/// `text` in reports.
inline Matcher client_record(ClientKind kind, std::string field, nlohmann::json value,
                             std::string text) {
  return Matcher{Source::client,
                 kind,
                 {{std::move(field), FieldTest::Op::equals, std::move(value)}},
                 std::move(text)};
}

/// An expectation called `label` on what `what` matches, held by `quantifier`.
inline Expectation expectation(std::string label, Matcher what,
                               Quantifier quantifier = Quantifier::exists) {
  Expectation e;
  e.label = std::move(label);
  e.what = std::move(what);
  e.quantifier = quantifier;
  return e;
}

/// The records of one kind, in time order.
inline std::vector<Record> of(const ScenarioOutcome& o, RecordKind kind) {
  std::vector<Record> out;
  for (const auto& r : o.timeline.records())
    if (r.kind == kind) out.push_back(r);
  return out;
}

/// The records of one kind before the run stopped the client.
inline std::vector<Record> in_session(const ScenarioOutcome& o, RecordKind kind) {
  std::vector<Record> out;
  for (const auto& r : o.timeline.records())
    if (r.kind == kind && r.at < o.session_end) out.push_back(r);
  return out;
}

}  // namespace hil::harness::test
