#pragma once
// Scripted behaviours written in YAML: a file of their own (`hil mock
// --behaviours`) or a node inside a scenario. The language is described in
// docs/mocks.md ("Scripted behaviour").

#include <string>
#include <string_view>
#include <vector>

#include "config/error.hpp"
#include "mocks/behaviour.hpp"

namespace YAML {
class Node;
}

namespace hil::mocks {

/// Reads a behaviours file. Throws config::ConfigError.
std::vector<Behaviour> load_behaviours(const std::string& path);
/// From a node: a map with `behaviours`, or the list itself.
std::vector<Behaviour> parse_behaviours(const YAML::Node& node, const std::string& source_name);
std::vector<Behaviour> parse_behaviours_text(std::string_view yaml, const std::string& source_name);

}  // namespace hil::mocks
