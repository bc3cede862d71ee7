#pragma once
// Fault profiles written in YAML: a file of their own, or a node embedded in
// a scenario file. The language is described in docs/faults.md.

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "link/faults/profile.hpp"

namespace YAML {
class Node;
}

namespace hil::link {

/// A profile that cannot load. what() reads "SOURCE:LINE:COLUMN: MESSAGE",
/// e.g. "faults.yaml:7:5: rule 2 (fragment): 'sizes' must be [min, max]
/// with 1 <= min <= max". Line and column count from 1; 0 when unknown (a
/// file that cannot be read).
class FaultProfileError : public std::runtime_error {
 public:
  FaultProfileError(std::string source, int line, int column, const std::string& message);
  const std::string& source() const { return source_; }
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  std::string source_;
  int line_;
  int column_;
};

/// Reads a profile file. Throws FaultProfileError.
FaultProfile load_fault_profile(const std::string& path);

/// A profile from a YAML node: a map with `rules` (and an optional
/// `description`), or the list of rules itself. `source_name` is the file
/// the node came from, for error messages. Throws FaultProfileError.
FaultProfile parse_fault_profile(const YAML::Node& node, const std::string& source_name);

/// A profile from YAML text (tests, command lines). Throws FaultProfileError.
FaultProfile parse_fault_profile_text(std::string_view yaml, const std::string& source_name);

/// "250ms", "2s", "1.5s", "500us", "100ns": a non-negative number and a
/// unit; nullopt for anything else (a bare number has no unit and is refused).
std::optional<Duration> parse_duration(std::string_view text);

}  // namespace hil::link
