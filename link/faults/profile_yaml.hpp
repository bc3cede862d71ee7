#pragma once
// Fault profiles written in YAML: a file of their own, or a node embedded in
// a scenario file. The language is described in docs/faults.md.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "config/error.hpp"
#include "link/faults/profile.hpp"

namespace YAML {
class Node;
}

namespace hil::link {

/// Reads a profile file. Throws config::ConfigError.
FaultProfile load_fault_profile(const std::string& path);

/// A profile from a YAML node: a map with `rules` (and an optional
/// `description`), or the list of rules itself. `source_name` is the file
/// the node came from, for error messages. Throws config::ConfigError.
FaultProfile parse_fault_profile(const YAML::Node& node, const std::string& source_name);

/// One rule from a YAML map (an entry of a profile's `rules`), the
/// `index`-th (1-based) for error messages. Throws config::ConfigError.
FaultRule parse_fault_rule(const YAML::Node& node, const std::string& source_name,
                           std::size_t index = 1);

/// The keys a rule of `kind` takes ("kind", "name", "direction" included),
/// sorted.
std::vector<std::string> rule_keys(FaultKind kind);

/// A profile from YAML text (tests, command lines). Throws config::ConfigError.
FaultProfile parse_fault_profile_text(std::string_view yaml, const std::string& source_name);

}  // namespace hil::link
