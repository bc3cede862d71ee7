#include "harness/scenario_parts.hpp"

namespace hil::harness::scenario_parts {
namespace {

/// `variables:` and their ${name} in every other scalar.
class VariableReader : public config::Reader {
 public:
  explicit VariableReader(ScenarioFacts& facts) : config::Reader(facts.file), facts_(facts) {}

  static bool valid_variable_name(std::string_view name) {
    if (name.empty()) return false;
    for (std::size_t i = 0; i < name.size(); ++i) {
      const char c = name[i];
      const bool letter = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
      const bool digit = c >= '0' && c <= '9';
      if (!(letter || (i > 0 && (digit || c == '-')))) return false;
    }
    return true;
  }

  void read_variables(const YAML::Node& root, const std::map<std::string, std::string>& overrides) {
    if (auto vars = root["variables"]) {
      if (!vars.IsMap() && !vars.IsNull()) {
        fail(vars, "'variables' must be a map of names to values, like {speed: 50}");
      }
      if (vars.IsMap()) {
        std::set<std::string> seen;
        for (auto it : vars) {
          const std::string name = scalar(it.first, "a variable name");
          if (!valid_variable_name(name)) {
            fail(it.first, "variable name '" + name +
                               "' must start with a letter or '_' and hold only letters, digits, "
                               "'_' and '-'");
          }
          if (!seen.insert(name).second) fail(it.first, "variable '" + name + "' is given twice");
          if (it.second.IsNull()) {
            variables_[name] = "";
          } else {
            variables_[name] = scalar(it.second, "variable '" + name + "'");
          }
        }
      }
    }
    for (const auto& [name, value] : overrides)
      variables_[name] = value;
  }

  /// Replaces ${name} in every scalar under `node`; "$${" stays a literal "${".
  void substitute(YAML::Node node) {
    if (node.IsMap()) {
      for (auto it : node)
        substitute(it.second);
      return;
    }
    if (node.IsSequence()) {
      for (auto item : node)
        substitute(item);
      return;
    }
    if (!node.IsScalar()) return;
    const std::string& text = node.Scalar();
    if (text.find('$') == std::string::npos) return;
    std::string out;
    bool changed = false;
    for (std::size_t i = 0; i < text.size();) {
      if (text.compare(i, 3, "$${") == 0) {
        out += "${";
        i += 3;
        changed = true;
        continue;
      }
      if (text.compare(i, 2, "${") == 0) {
        const auto close = text.find('}', i + 2);
        if (close == std::string::npos) {
          fail_inside(node, static_cast<int>(i) + 1,
                      "'${' without a closing '}' (write $${ for a literal ${)");
        }
        const std::string name = text.substr(i + 2, close - i - 2);
        const auto found = variables_.find(name);
        if (found == variables_.end()) {
          Keys names;
          for (const auto& [n, v] : variables_)
            names.push_back(n);
          fail_inside(node, static_cast<int>(i) + 1,
                      "variable '" + name + "' is not defined (" +
                          (names.empty() ? std::string("the scenario has no 'variables'")
                                         : "defined: " + join(names)) +
                          ")" + config::did_you_mean(name, names));
        }
        out += found->second;
        i = close + 1;
        changed = true;
        continue;
      }
      out += text[i++];
    }
    if (changed) {
      facts_.substituted.insert({node.Mark().line, node.Mark().column});
      node = out;
    }
  }

  std::map<std::string, std::string> variables_;

 private:
  ScenarioFacts& facts_;
};

}  // namespace

std::map<std::string, std::string> expand_variables(
    ScenarioFacts& facts, YAML::Node root, const std::map<std::string, std::string>& overrides) {
  VariableReader reader(facts);
  reader.read_variables(root, overrides);
  for (auto it : root) {
    if (it.first.Scalar() != "variables") reader.substitute(it.second);
  }
  return reader.variables_;
}

}  // namespace hil::harness::scenario_parts
