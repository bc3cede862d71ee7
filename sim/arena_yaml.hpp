#pragma once
// Arenas written in YAML, one file per world in scenarios/worlds/. The
// format is described in docs/simulation.md.

#include <string>
#include <string_view>

#include "config/error.hpp"
#include "sim/arena.hpp"

namespace YAML {
class Node;
}

namespace hil::sim {

/// Reads an arena file. Throws config::ConfigError.
Arena load_arena(const std::string& path);

/// An arena from a YAML node (a world file, or a node embedded in a scenario
/// file); `source_name` names the file for error messages. Throws config::ConfigError.
Arena parse_arena(const YAML::Node& node, const std::string& source_name);

/// An arena from YAML text. Throws config::ConfigError.
Arena parse_arena_text(std::string_view yaml, const std::string& source_name);

/// The arena as YAML that parse_arena_text reads back to an equal arena.
std::string to_yaml(const Arena& arena);

}  // namespace hil::sim
