#pragma once
// Scenario files written in YAML by QA; the language is in
// docs/scenarios.md and its JSON Schema in scenarios/schema.json.

#include <map>
#include <string>
#include <string_view>

#include "config/error.hpp"
#include "harness/scenario.hpp"

namespace hil::harness {

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
/// Both throw config::ConfigError, at the node a problem is about.
Scenario load_scenario(const std::string& path,
                       const std::map<std::string, std::string>& overrides = {},
                       const LoadOptions& options = {});
Scenario parse_scenario_text(std::string_view yaml, const std::string& file_name,
                             const std::map<std::string, std::string>& overrides = {},
                             const LoadOptions& options = {});

}  // namespace hil::harness
