#include "control/routes_config.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <set>

#include "config/yaml.hpp"
#include "link/faults/profile_yaml.hpp"

namespace hil::control {
namespace {

const config::Keys kRouteKeys = {"name",     "protocol", "profile", "listen",
                                 "upstream", "enabled",  "faults",  "toxics"};

/// A YAML node as the JSON a request body would hold: plain true/false
/// and numbers become JSON's, quoted scalars stay text.
nlohmann::json yaml_to_json(const YAML::Node& node) {
  if (node.IsMap()) {
    nlohmann::json object = nlohmann::json::object();
    for (const auto& item : node)
      object[item.first.Scalar()] = yaml_to_json(item.second);
    return object;
  }
  if (node.IsSequence()) {
    nlohmann::json array = nlohmann::json::array();
    for (const auto& item : node)
      array.push_back(yaml_to_json(item));
    return array;
  }
  if (!node.IsScalar()) return nullptr;
  const std::string& text = node.Scalar();
  if (node.Tag() == "!") return text;  // quoted: text, whatever it reads
  if (text == "true") return true;
  if (text == "false") return false;
  if (text == "null" || text == "~") return nullptr;
  if (const auto whole = config::parse_whole(text)) return *whole;
  if (const auto number = config::parse_number(text)) return *number;
  return text;
}

/// The node within `item` at a dotted path ("attributes.latency"), or the
/// deepest one that exists on the way.
YAML::Node node_at(const YAML::Node& item, const std::string& path) {
  const std::size_t dot = path.find('.');
  const std::string part = path.substr(0, dot);
  if (!item.IsMap() || !item[part]) return item;
  const YAML::Node next = item[part];
  return dot == std::string::npos ? next : node_at(next, path.substr(dot + 1));
}

/// The node an ApiError's "FIELD.PART: ..." names within `item`.
YAML::Node node_named(const YAML::Node& item, const std::string& message) {
  const std::size_t colon = message.find(": ");
  if (colon == std::string::npos) return item;
  return node_at(item, message.substr(0, colon));
}

class RoutesReader : public config::Reader {
 public:
  explicit RoutesReader(const std::string& file) : config::Reader(file) {}

  std::vector<RouteSpec> read(const YAML::Node& root) const {
    if (!root.IsMap()) fail(root, "a routes file is a map with 'routes', not a " + shape(root));
    check_keys(root, {"routes"}, "");
    const YAML::Node list = required(root, "routes", "the routes file");
    if (!list.IsSequence()) fail(list, "routes must be a list of routes, not a " + shape(list));
    std::vector<RouteSpec> specs;
    std::set<std::string> names;
    for (std::size_t i = 0; i < list.size(); ++i) {
      specs.push_back(route(list[i], i + 1));
      if (!names.insert(specs.back().name).second) {
        fail(list[i]["name"], "route " + std::to_string(i + 1) + ": the name '" +
                                  specs.back().name + "' is taken by an earlier route");
      }
    }
    return specs;
  }

 private:
  RouteSpec route(const YAML::Node& node, std::size_t number) const {
    std::string where = "route " + std::to_string(number);
    if (!node.IsMap()) fail(node, where + " must be a map, not a " + shape(node));
    check_keys(node, kRouteKeys, where);
    RouteSpec spec;
    spec.name = scalar(required(node, "name", where), where + ": name");
    where += " (" + spec.name + ")";
    spec.upstream = scalar(required(node, "upstream", where), where + ": upstream");
    if (node["listen"]) spec.listen = scalar(node["listen"], where + ": listen");
    if (node["protocol"]) spec.protocol = scalar(node["protocol"], where + ": protocol");
    if (node["profile"]) spec.profile = scalar(node["profile"], where + ": profile");
    if (node["enabled"]) spec.enabled = boolean(node["enabled"], where + ": enabled");
    if (node["faults"]) spec.faults = faults(node["faults"], where);
    try {
      check_route_spec(spec);
    } catch (const ApiError& e) {
      fail(node_named(node, e.what()), where + ": " + e.what());
    }
    if (const YAML::Node toxics = node["toxics"]) {
      if (!toxics.IsSequence())
        fail(toxics, where + ": toxics must be a list of toxics, not a " + shape(toxics));
      for (std::size_t i = 0; i < toxics.size(); ++i) {
        spec.toxics.push_back(toxic(toxics[i], where + ": toxic " + std::to_string(i + 1)));
        for (std::size_t j = 0; j + 1 < spec.toxics.size(); ++j) {
          if (spec.toxics[j].name == spec.toxics.back().name) {
            fail(toxics[i], where + ": toxic " + std::to_string(i + 1) + ": the name '" +
                                spec.toxics.back().name + "' is taken by toxic " +
                                std::to_string(j + 1));
          }
        }
      }
    }
    return spec;
  }

  /// A profile file (relative to this file) or the rules themselves.
  link::FaultProfile faults(const YAML::Node& node, const std::string& where) const {
    if (node.IsScalar()) {
      std::filesystem::path path = node.Scalar();
      if (path.is_relative()) path = std::filesystem::path(file()).parent_path() / path;
      if (!std::filesystem::exists(path)) {
        fail(node, where + ": faults: no fault profile at " + path.string() +
                       " (a path is relative to this file)");
      }
      return link::load_fault_profile(path.string());
    }
    if (!node.IsMap() && !node.IsSequence()) {
      fail(node, where +
                     ": faults must be a profile file, a list of rules or a map with "
                     "'rules', not a " +
                     shape(node));
    }
    return link::parse_fault_profile(node, file());
  }

  Toxic toxic(const YAML::Node& node, const std::string& where) const {
    if (!node.IsMap()) fail(node, where + " must be a map, not a " + shape(node));
    try {
      return parse_toxic(yaml_to_json(node), link::Time{0});
    } catch (const ApiError& e) {
      fail(node_named(node, e.what()), where + ": " + e.what());
    }
  }
};

}  // namespace

std::vector<RouteSpec> parse_routes_text(std::string_view yaml, const std::string& source_name) {
  const RoutesReader reader(source_name);
  return reader.read(reader.parse(yaml));
}

std::vector<RouteSpec> load_routes_file(const std::string& path) {
  return parse_routes_text(config::read_file(path, "routes file"), path);
}

}  // namespace hil::control
