#pragma once
// Which files are scenarios: the one rule `hil run` finds them by and `hil
// report merge --expect` checks shards against, so both see the same set.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace hil::harness {

/// A path named to the search that cannot be used; what() names it.
class ScenarioSearchError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Whether `path` is a scenario file by its looks: *.yaml or *.yml with a
/// top-level `car:` and `steps:`. Read as text, so a file with a YAML
/// mistake is still found (and loading it says what is wrong).
bool looks_like_scenario(const std::filesystem::path& path);

struct ScenarioSearch {
  std::vector<std::string> files;          ///< sorted, each once, paths made normal
  std::vector<std::string> not_scenarios;  ///< YAML files in the folders that are not scenarios
};

/// The scenario files named by `paths`: a folder gives every scenario file
/// under it, a file is taken as it is (it is a scenario: if it is not one,
/// loading it says why). Throws ScenarioSearchError for a path that does
/// not exist or a folder that cannot be read.
ScenarioSearch find_scenario_files(const std::vector<std::string>& paths);

/// Whether `have` holds any of `wanted`.
bool has_any_tag(const std::vector<std::string>& have, const std::vector<std::string>& wanted);

}  // namespace hil::harness
