#pragma once
// Scripted behaviours written in YAML: a file of their own (`hil mock
// --behaviours`) or a node inside a scenario. The language is described in
// docs/mocks.md ("Scripted behaviour").

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "mocks/behaviour.hpp"

namespace YAML {
class Node;
}

namespace hil::mocks {

/// Behaviours that cannot load. what() reads "SOURCE:LINE:COLUMN: MESSAGE",
/// e.g. "desk.yaml:4:11: behaviour 1 (reject): 'times' must be a whole
/// number >= 1". Line and column count from 1; 0 when unknown.
class BehaviourError : public std::runtime_error {
 public:
  BehaviourError(std::string source, int line, int column, const std::string& message);
  const std::string& source() const { return source_; }
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  std::string source_;
  int line_;
  int column_;
};

/// Reads a behaviours file. Throws BehaviourError.
std::vector<Behaviour> load_behaviours(const std::string& path);
/// From a node: a map with `behaviours`, or the list itself.
std::vector<Behaviour> parse_behaviours(const YAML::Node& node, const std::string& source_name);
std::vector<Behaviour> parse_behaviours_text(std::string_view yaml, const std::string& source_name);

}  // namespace hil::mocks
