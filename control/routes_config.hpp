#pragma once
// A routes file: several proxy routes for one `hil proxy --config FILE`,
// like Toxiproxy's config file, in YAML (JSON is YAML too). Each route
// names its protocol, profile, listen and upstream, and may declare hil
// fault rules (`faults:`, a profile file or inline rules) and Toxiproxy
// toxics (`toxics:`), active from the first connection. docs/proxy-api.md
// has the format.

#include <string>
#include <string_view>
#include <vector>

#include "control/proxy_hub.hpp"

namespace hil::control {

/// Reads a routes file. Throws config::ConfigError with the file, line and
/// column of what is wrong (a route field, a rule, a toxic attribute).
std::vector<RouteSpec> load_routes_file(const std::string& path);
/// The same from text; `source_name` names it in errors.
std::vector<RouteSpec> parse_routes_text(std::string_view yaml, const std::string& source_name);

}  // namespace hil::control
