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

/// How a scenario file is read, beyond its variables.
struct LoadOptions {
  /// Let the scenario name files outside its root (absolute paths, `../`
  /// past the root, symlinks pointing out): hil run --allow-outside-paths.
  bool allow_outside_paths = false;
};

/// The folder a scenario's files must stay in, as an absolute path: the
/// parent of the folder the scenario file is in (its library, e.g.
/// scenarios/ for scenarios/logi/release.yaml, so ../faults/x.yaml is
/// inside). The same whichever way the file was named on the command line.
std::string scenario_root(const std::string& scenario_file);

/// `overrides` replace the file's variables (hil run --set name=value).
Scenario load_scenario(const std::string& path,
                       const std::map<std::string, std::string>& overrides = {},
                       const LoadOptions& options = {});
Scenario parse_scenario_text(std::string_view yaml, const std::string& file_name,
                             const std::map<std::string, std::string>& overrides = {},
                             const LoadOptions& options = {});

}  // namespace hil::harness
