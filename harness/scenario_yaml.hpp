#pragma once
// Scenario files written in YAML by QA; the language is in
// docs/scenarios.md and its JSON Schema in scenarios/schema.json.

#include <map>
#include <stdexcept>
#include <string>
#include <string_view>

#include "harness/scenario.hpp"

namespace hil::harness {

/// A scenario that cannot load. what() reads "FILE:LINE:COLUMN: MESSAGE",
/// e.g. "release.yaml:12:9: step 3: unknown LOGI action 'pres FWD'
/// (expected connect, disconnect, speed N, ...)". Line and column count
/// from 1; 0 when unknown (a file that cannot be read).
class ScenarioError : public std::runtime_error {
 public:
  ScenarioError(std::string file, int line, int column, const std::string& message);
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  std::string file_;
  int line_;
  int column_;
};

/// `overrides` replace the file's variables (hil run --set name=value).
Scenario load_scenario(const std::string& path,
                       const std::map<std::string, std::string>& overrides = {});
Scenario parse_scenario_text(std::string_view yaml, const std::string& file_name,
                             const std::map<std::string, std::string>& overrides = {});

}  // namespace hil::harness
