#include "harness/scenario_parts.hpp"

#include "harness/reference_settings.hpp"

namespace hil::harness::scenario_parts {
namespace {

/// `client:`: the reference client and its settings, or an external program.
class ClientReader : public config::Reader {
 public:
  explicit ClientReader(const ScenarioFacts& facts) : config::Reader(facts.file), facts_(facts) {}

  ClientSpec client(const YAML::Node& n) const {
    if (n.IsScalar()) {
      if (n.Scalar() == "reference") return ReferenceClient{};
      fail(n, "'client' must be reference, {reference: {real_time: true}} or {exec: \"COMMAND\"}");
    }
    if (!n.IsMap()) {
      fail(n, "'client' must be reference, {reference: {real_time: true}} or {exec: \"COMMAND\"}");
    }
    if (n["reference"]) {
      check_keys(n, {"reference"}, "'client'");
      ReferenceClient r;
      const auto ref = n["reference"];
      if (ref.IsMap()) {
        check_keys(ref, {"real_time", "settings"}, "'client: reference'");
        if (auto rt = ref["real_time"]) r.real_time = boolean(rt, "'real_time'");
        if (auto settings = ref["settings"]) r.settings = reference_settings_of(settings);
      } else if (!ref.IsNull()) {
        fail(ref, "'reference' takes a map like {real_time: true, settings: {...}}, or nothing");
      }
      return r;
    }
    if (n["exec"]) {
      check_keys(n, {"exec", "startup_timeout"}, "'client'");
      ExecClient e;
      const auto cmd = n["exec"];
      e.command = scalar(cmd, "'exec'");
      if (trim(e.command).empty()) fail(cmd, "'exec' must be the command that starts the client");
      check_placeholders(cmd);
      if (auto t = n["startup_timeout"]) e.startup_timeout = duration(t, "'startup_timeout'");
      return e;
    }
    check_keys(n, {"reference", "exec", "startup_timeout"}, "'client'");
    fail(n, "'client' needs 'reference' or 'exec'");
  }

  /// `settings: {max_retries: 0, reconnect_delays: [1s, 2s]}`: options of
  /// the car's client library, each checked by the library's own rules.
  nlohmann::json reference_settings_of(const YAML::Node& n) const {
    const std::string where = "'client: reference: settings'";
    if (!n.IsMap()) fail(n, where + " must be a map like {max_retries: 0}");
    Keys names;
    for (const auto& s : reference_settings(facts_.car, facts_.profile))
      names.push_back(s.name);
    check_keys(n, names, where + " (" + car_title(facts_.car) + ")");
    auto out = nlohmann::json::object();
    for (auto it : n) {
      const std::string name = it.first.Scalar();
      nlohmann::json value;
      if (it.second.IsSequence()) {
        value = nlohmann::json::array();
        for (const auto& item : it.second)
          value.push_back(scalar(item, where + ": '" + name + "'"));
      } else {
        value = scalar(it.second, where + ": '" + name + "'");
      }
      if (auto problem = reference_setting_problem(facts_.car, name, value, facts_.profile)) {
        fail(it.second, where + ": " + *problem);
      }
      out[name] = std::move(value);
    }
    return out;
  }

  void check_placeholders(const YAML::Node& cmd) const {
    static const Keys kPlaceholders = {"{host}", "{port}",    "{endpoint}",
                                       "{pty}",  "{actions}", "{scenario}"};
    const std::string& text = cmd.Scalar();
    for (std::size_t open = text.find('{'); open != std::string::npos;
         open = text.find('{', open + 1)) {
      const auto close = text.find('}', open);
      if (close == std::string::npos) break;
      const std::string word = text.substr(open, close - open + 1);
      const bool plain_word = std::all_of(word.begin() + 1, word.end() - 1, [](char c) {
        return (c >= 'a' && c <= 'z') || c == '_';
      });
      if (plain_word && word.size() > 2 && !contains(kPlaceholders, word)) {
        fail_inside(cmd, static_cast<int>(open) + 1,
                    "unknown placeholder '" + word + "' (known: " + join(kPlaceholders) + ")" +
                        config::did_you_mean(word, kPlaceholders));
      }
    }
  }

 private:
  const ScenarioFacts& facts_;
};

}  // namespace

ClientSpec read_client(const ScenarioFacts& facts, const YAML::Node& n) {
  return ClientReader(facts).client(n);
}

}  // namespace hil::harness::scenario_parts
