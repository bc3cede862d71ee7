#pragma once
// The parts of the scenario loader. harness/scenario_yaml.cpp reads a
// scenario file top-down (variables, car, client, faults, steps, schedule,
// expectations) and hands each part to the reader of its concept:
//
//   scenario_variables.cpp     ${name} and hil run --set
//   scenario_files.cpp         files a scenario names (world, fault profiles)
//   scenario_client.cpp        `client:` (reference and its settings, exec)
//   scenario_steps.cpp         steps: operator actions, waits, car behaviours, obstacles
//   scenario_matchers.cpp      matchers: the four sources' dispatch, wire frames, anchors
//   scenario_event_matchers.cpp client, sim, fault, car and step matchers
//   scenario_expectations.cpp  `schedule:` and `expect:`
//
// Every part fails through config::Reader, so every problem is a
// config::ConfigError at the node it is about. Internal to hil::harness.

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "config/yaml.hpp"
#include "harness/scenario.hpp"

namespace hil::harness::scenario_parts {

using config::closest;
using config::join;
using config::Keys;

/// What every part of a scenario file is read against: the file, the car
/// and profile it names, and what earlier parts found.
struct ScenarioFacts {
  std::string file;
  std::filesystem::path dir;  ///< the scenario's folder
  bool allow_outside_paths = false;
  mocks::CarKind car = mocks::CarKind::logi;
  std::string profile;
  /// Every step's text (setup, steps, teardown, schedule), read before the
  /// steps themselves: step matchers anywhere refer to them.
  Keys step_texts;
  /// Scalars (by line and column) that held a ${variable}.
  std::set<std::pair<int, int>> substituted;

  bool was_substituted(const YAML::Node& n) const {
    return substituted.contains({n.Mark().line, n.Mark().column});
  }
};

inline const Keys kStepKeys = {"do", "wait", "wait_until", "car", "faults", "obstacle"};
inline const Keys kMatcherSources = {"wire", "client", "sim", "step", "fault", "car"};
inline const Keys kWireDirections = {"received", "sent_by_client", "sent_by_car",
                                     "received_by_client"};
/// What a wire frame matcher may test besides the frame kind.
inline const Keys kFrameKeys = {"valid", "error", "text", "hex", "message", "fields"};
inline const Keys kWindowKeys = {"within", "after", "at", "between"};
inline const Keys kQuantifierKeys = {"never", "count", "at_least", "at_most", "times", "always"};

inline bool contains(const Keys& keys, std::string_view key) {
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}
/// `text` without leading and trailing white space.
std::string trim(std::string_view text);
/// "LOGI", "WR8", "Arduino", "Leka", for messages.
std::string car_title(mocks::CarKind car);
inline FieldTest field_test(std::string field, FieldTest::Op op, nlohmann::json value) {
  return FieldTest{std::move(field), op, std::move(value)};
}

// scenario_variables.cpp
/// Reads `variables:`, lets `overrides` replace them, and substitutes every
/// ${name} in the other keys of `root`. Returns the variables in force.
std::map<std::string, std::string> expand_variables(
    ScenarioFacts& facts, YAML::Node root, const std::map<std::string, std::string>& overrides);

// scenario_files.cpp
/// A file named relative to the scenario's folder; it must exist and,
/// unless allowed, stay inside the scenario's root.
std::string read_existing_file(const ScenarioFacts& facts, const YAML::Node& n,
                               const std::string& what);
/// off, a profile file, {file: FILE} or {rules: [...]}.
link::FaultProfile read_faults(const ScenarioFacts& facts, const YAML::Node& n,
                               const std::string& what);

// scenario_client.cpp
ClientSpec read_client(const ScenarioFacts& facts, const YAML::Node& n);

// scenario_steps.cpp
/// How a step reads in reports and in the timeline's step records.
std::string step_text(const YAML::Node& step, const std::string& key);
void collect_step_texts(ScenarioFacts& facts, const YAML::Node& list);
std::vector<Step> read_steps(const ScenarioFacts& facts, const YAML::Node& list,
                             const std::string& key, const std::string& prefix);
Step read_step(const ScenarioFacts& facts, const YAML::Node& n, const std::string& where,
               const Keys& extra_keys);

// scenario_matchers.cpp
/// A matcher written alone (wait_until, schedule `when`).
Matcher read_matcher_node(const ScenarioFacts& facts, const YAML::Node& n,
                          const std::string& where);
/// The matcher keys of a map whose other keys the caller checked.
Matcher read_matcher(const ScenarioFacts& facts, const YAML::Node& n, const std::string& where);
/// An anchor: a step's text, a matcher map (with occurrence and offset) or,
/// when `allow_times`, a run time.
Anchor read_anchor(const ScenarioFacts& facts, const YAML::Node& n, const std::string& where,
                   bool allow_times);
/// `occurrence` and `offset` of `n` into `a`.
void read_anchor_occurrence(const ScenarioFacts& facts, const YAML::Node& n, Anchor& a,
                            const std::string& where);

// scenario_event_matchers.cpp: the value under the source's key.
Matcher read_client_matcher(const ScenarioFacts& facts, const YAML::Node& v,
                            const std::string& where);
Matcher read_sim_matcher(const ScenarioFacts& facts, const YAML::Node& v, const std::string& where);
Matcher read_fault_matcher(const ScenarioFacts& facts, const YAML::Node& v,
                           const std::string& where);
Matcher read_car_matcher(const ScenarioFacts& facts, const YAML::Node& v, const std::string& where);
/// `phase` is "start" or "end".
Matcher read_step_matcher(const ScenarioFacts& facts, const YAML::Node& v, const std::string& phase,
                          const std::string& where);

// scenario_expectations.cpp
std::vector<ScheduledStep> read_schedule(const ScenarioFacts& facts, const YAML::Node& list);
std::vector<Expectation> read_expectations(const ScenarioFacts& facts, const YAML::Node& list);

}  // namespace hil::harness::scenario_parts
