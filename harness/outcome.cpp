#include "harness/outcome.hpp"

namespace hil::harness {

std::string ExpectationOutcome::where() const {
  return line > 0 ? "expect line " + std::to_string(line) : std::string("at the end");
}

bool ScenarioOutcome::passed() const {
  if (was_skipped()) return true;
  if (!error.empty()) return false;
  for (const auto& s : steps)
    if (!s.ok) return false;
  for (const auto& e : expectations)
    if (!e.passed) return false;
  return true;
}

std::string ScenarioOutcome::first_failure() const {
  if (!error.empty()) return error;
  for (const auto& s : steps)
    if (!s.ok) return "step line " + std::to_string(s.line) + " (" + s.text + "): " + s.reason;
  for (const auto& e : expectations)
    if (!e.passed) return e.where() + ": " + e.message;
  return {};
}

}  // namespace hil::harness
