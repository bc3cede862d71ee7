#pragma once
// Arenas written in YAML, one file per world in scenarios/worlds/. The
// format is described in docs/simulation.md.

#include <stdexcept>
#include <string>
#include <string_view>

#include "sim/arena.hpp"

namespace YAML {
class Node;
}

namespace hil::sim {

/// An arena file that cannot load. what() reads "SOURCE:LINE:COLUMN: FIELD:
/// MESSAGE", e.g. "lab.yaml:12:15: obstacles[1].circle.radius_m: expected a
/// positive number of metres, got '-0.2'". Line and column count from 1; 0
/// when unknown (a file that cannot be read).
class ArenaError : public std::runtime_error {
 public:
  ArenaError(std::string source, int line, int column, const std::string& message);
  const std::string& source() const { return source_; }
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  std::string source_;
  int line_;
  int column_;
};

/// Reads an arena file. Throws ArenaError.
Arena load_arena(const std::string& path);

/// An arena from a YAML node (a world file, or a node embedded in a scenario
/// file); `source_name` names the file for error messages. Throws ArenaError.
Arena parse_arena(const YAML::Node& node, const std::string& source_name);

/// An arena from YAML text. Throws ArenaError.
Arena parse_arena_text(std::string_view yaml, const std::string& source_name);

/// The arena as YAML that parse_arena_text reads back to an equal arena.
std::string to_yaml(const Arena& arena);

}  // namespace hil::sim
