#include "harness/scenario_parts.hpp"

#include "client/arduino/operator.hpp"
#include "client/leka/operator.hpp"
#include "client/logi/operator.hpp"
#include "client/wr8/operator.hpp"
#include "client/wr8/svgui_operator.hpp"
#include "mocks/behaviour_yaml.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::harness::scenario_parts {
namespace {
/// What the car's operator-language parser says about one action: nullopt
/// when it is an action, else the 1-based column and the message.
std::optional<std::pair<int, std::string>> check_action(mocks::CarKind car,
                                                        std::string_view profile,
                                                        const std::string& text) {
  if (car == mocks::CarKind::wr8) {
    if (const auto version = protocol::wr8::svgui::version_of_profile(profile)) {
      const auto r = client::wr8::parse_svgui_line(text, *version);
      if (r.error) return std::pair{static_cast<int>(r.error->column), r.error->message};
      if (!r.action) return std::pair{1, std::string("an empty action")};
      return std::nullopt;
    }
  }
  switch (car) {
    case mocks::CarKind::logi: {
      const auto r = client::logi::parse_operator_action(text);
      if (r.error) return std::pair{r.error->column, r.error->message};
      if (!r.action) return std::pair{1, std::string("an empty action")};
      return std::nullopt;
    }
    case mocks::CarKind::wr8: {
      const auto r = client::wr8::parse_operator_line(text);
      if (r.error) return std::pair{static_cast<int>(r.error->column), r.error->message};
      if (!r.action) return std::pair{1, std::string("an empty action")};
      return std::nullopt;
    }
    case mocks::CarKind::arduino: {
      const auto r = client::arduino::parse_operator_line(text);
      if (r.error) return std::pair{static_cast<int>(r.error->column), r.error->message};
      if (!r.action) return std::pair{1, std::string("an empty action")};
      if (std::holds_alternative<client::arduino::HistoryCommand>(*r.action) ||
          std::holds_alternative<client::arduino::SaveLogCommand>(*r.action) ||
          std::holds_alternative<client::arduino::QuitCommand>(*r.action)) {
        return std::pair{1, "'" + client::arduino::to_text(*r.action) +
                                "' is a command of the interactive prompt, not an operator "
                                "action"};
      }
      return std::nullopt;
    }
    case mocks::CarKind::leka: {
      const auto r = client::leka::parse_operator_line(text);
      if (r.error) return std::pair{static_cast<int>(r.error->column), r.error->message};
      if (!r.action) return std::pair{1, std::string("an empty action")};
      return std::nullopt;
    }
  }
  return std::nullopt;
}

/// Steps: operator actions (checked by the car's own operator language), waits, car behaviours,
/// fault changes and obstacles.
class StepReader : public config::Reader {
 public:
  explicit StepReader(const ScenarioFacts& facts) : config::Reader(facts.file), facts_(facts) {}

  /// How a step reads in reports and in the timeline's step records.

  std::vector<Step> steps(const YAML::Node& list, const std::string& key,
                          const std::string& prefix) const {
    if (list.IsNull()) return {};
    if (!list.IsSequence()) fail(list, "'" + key + "' must be a list of steps");
    std::vector<Step> out;
    std::size_t index = 0;
    for (const auto& item : list) {
      ++index;
      out.push_back(step(item, prefix + std::to_string(index), {}));
    }
    return out;
  }

  Step step(const YAML::Node& n, const std::string& where, const Keys& extra_keys) const {
    Step s;
    s.line = n.Mark().line + 1;
    if (n.IsScalar()) {
      s.text = trim(n.Scalar());
      s.action = action(n, where);
      return s;
    }
    if (!n.IsMap()) {
      fail(n, where + ": a step is an operator action (\"speed 50\") or a map with one of " +
                  join(kStepKeys));
    }
    Keys allowed = kStepKeys;
    allowed.insert(allowed.end(), {"timeout", "expect"});
    allowed.insert(allowed.end(), extra_keys.begin(), extra_keys.end());
    check_keys(n, allowed, where);
    const std::string key =
        one_key(n, kStepKeys, [&](const std::string& first, const std::string& second) {
          return where + ": a step does one thing: '" + first + "' and '" + second +
                 "' are two steps";
        });
    if (key.empty()) fail(n, where + ": a step needs one of " + join(kStepKeys));
    if (n["timeout"] && key != "wait_until") {
      fail(n["timeout"], where + ": 'timeout' belongs to wait_until");
    }
    s.text = step_text(n, key);
    if (auto e = n["expect"]) read_expected_failure(e, where, s);
    const YAML::Node v = n[key];
    if (key == "do") {
      s.action = action(v, where);
    } else if (key == "wait") {
      s.action = WaitStep{duration(v, where + ": 'wait'")};
    } else if (key == "wait_until") {
      WaitUntilStep w;
      w.until = read_matcher_node(facts_, v, where + ": 'wait_until'");
      w.timeout = std::chrono::seconds(10);
      if (auto t = n["timeout"]) w.timeout = duration(t, where + ": 'timeout'");
      s.action = std::move(w);
    } else if (key == "car") {
      s.action = CarStep{behaviour(v, where)};
    } else if (key == "faults") {
      s.action = FaultsStep{read_faults(facts_, v, where + ": 'faults'")};
    } else {
      s.action = obstacle(v, where + ": 'obstacle'");
    }
    return s;
  }

  /// `expect: fail`, or `expect: {fail: "Not in manual mode"}` when the
  /// failure's reason must contain a text.
  void read_expected_failure(const YAML::Node& n, const std::string& where, Step& s) const {
    const std::string what = where + ": 'expect'";
    const std::string usage = " must be fail or {fail: \"words the reason contains\"}";
    if (n.IsScalar()) {
      if (n.Scalar() != "fail") {
        fail(n, what + usage + ", got '" + n.Scalar() + "'" +
                    config::did_you_mean(n.Scalar(), {"fail"}));
      }
      s.expect_failure = true;
      return;
    }
    if (!n.IsMap()) fail(n, what + usage);
    check_keys(n, {"fail"}, what);
    if (!n["fail"]) fail(n, what + usage);
    s.expect_failure = true;
    const YAML::Node reason = n["fail"];
    if (!reason.IsNull()) s.failure_contains = scalar(reason, what + ": 'fail'");
  }

  ActionStep action(const YAML::Node& n, const std::string& where) const {
    const std::string raw = scalar(n, where + ": the action");
    const std::string text = trim(raw);
    if (const auto problem = check_action(facts_.car, facts_.profile, text)) {
      const std::string message =
          where + ": " + car_title(facts_.car) + " action '" + text + "': " + problem->second;
      if (facts_.was_substituted(n)) fail(n, message);
      const auto lead = static_cast<int>(raw.find_first_not_of(" \t"));
      fail_inside(n, problem->first + (lead > 0 ? lead : 0), message);
    }
    return ActionStep{text};
  }

  mocks::Behaviour behaviour(const YAML::Node& n, const std::string& where) const {
    static const Keys kShort = {"reject",   "ignore", "mute_telemetry", "send",
                                "send_hex", "fault",  "clear_fault",    "close"};
    static const Keys kWhen = {"at", "after", "after_count", "name"};
    YAML::Node full;
    if (n.IsMap() && n["do"]) {
      full = n;
    } else if (n.IsScalar()) {
      const std::string& word = n.Scalar();
      if (word == "fault" || word == "clear-fault" || word == "clear_fault" || word == "close") {
        full["do"] = word == "clear_fault" ? std::string("clear-fault") : word;
      } else {
        fail(n, where + ": unknown car behaviour '" + word +
                    "' (a word: fault, clear_fault, close; or a map: " + join(kShort) +
                    ", or {do: ...} as in docs/mocks.md)" + config::did_you_mean(word, kShort));
      }
    } else if (n.IsMap()) {
      Keys allowed = kShort;
      allowed.insert(allowed.end(), kWhen.begin(), kWhen.end());
      allowed.push_back("do");
      check_keys(n, allowed, where);
      std::string action;
      for (const auto& k : kShort) {
        if (!n[k]) continue;
        if (!action.empty())
          fail(n[k], where + ": one behaviour per step ('" + action + "', '" + k + "')");
        action = k;
      }
      if (action.empty()) fail(n, where + ": a behaviour needs one of " + join(kShort));
      const YAML::Node v = n[action];
      if (action == "reject" || action == "ignore") {
        full["do"] = action;
        if (v.IsScalar()) {
          full["match"] = v;
        } else if (v.IsMap()) {
          check_keys(v, action == "reject" ? Keys{"match", "times"} : Keys{"match", "times", "for"},
                     where + ": '" + action + "'");
          for (auto it : v)
            full[it.first.Scalar()] = it.second;
        } else if (!v.IsNull()) {
          fail(v, where + ": '" + action +
                      "' takes a frame kind (MV) or a map like {match: MV, times: 2}");
        }
      } else if (action == "mute_telemetry") {
        full["do"] = "mute-telemetry";
        full["for"] = v;
      } else if (action == "send") {
        full["do"] = "send";
        full["text"] = v;
      } else if (action == "send_hex") {
        full["do"] = "send";
        full["hex"] = v;
      } else if (action == "close") {
        full["do"] = "close";
        if (!v.IsNull()) full["mode"] = v;
      } else {
        full["do"] = action == "clear_fault" ? std::string("clear-fault") : action;
        if (!v.IsNull() && !(v.IsScalar() && v.Scalar() == "true")) {
          fail(v, where + ": '" + action + "' takes no value");
        }
      }
      for (const auto& k : kWhen) {
        if (n[k]) full[k] = n[k];
      }
    } else {
      fail(n, where +
                  ": a car behaviour is a word (fault, close) or a map ({close: reset}, "
                  "{mute_telemetry: 3s}, {do: reject, match: MV})");
    }
    YAML::Node list(YAML::NodeType::Sequence);
    list.push_back(full);
    try {
      return mocks::parse_behaviours(list, file()).at(0);
    } catch (const config::ConfigError& e) {
      std::string message = e.message();
      if (message.starts_with("behaviour 1 ")) message = "car behaviour " + message.substr(12);
      if (e.line() == 0) fail(n, where + ": " + message);
      throw config::ConfigError(e.file(), e.line(), e.column(), where + ": " + message);
    }
  }

  ObstacleStep obstacle(const YAML::Node& n, const std::string& where) const {
    ObstacleStep o;
    if (n.IsScalar() && n.Scalar() == "remove") {
      o.add = false;
      return o;
    }
    if (!n.IsMap()) {
      fail(n, where + " must be {ahead: 0.3m}, {ahead: 0.3m, name: box}, remove or {remove: box}");
    }
    check_keys(n, {"ahead", "name", "remove"}, where);
    if (auto r = n["remove"]) {
      if (n["ahead"]) fail(n["ahead"], where + ": 'ahead' and 'remove' do not go together");
      if (n["name"]) fail(n["name"], where + ": write {remove: NAME}");
      o.add = false;
      o.name = scalar(r, "'remove'");
      return o;
    }
    const auto ahead = n["ahead"];
    if (!ahead) fail(n, where + ": 'ahead' is missing (how far in front of the car, like 0.3m)");
    o.ahead_m = metres(ahead, "'ahead'");
    if (auto name = n["name"]) o.name = scalar(name, "'name'");
    return o;
  }

 private:
  const ScenarioFacts& facts_;
};

}  // namespace

std::string step_text(const YAML::Node& step, const std::string& key) {
  const YAML::Node v = step[key];
  const auto flat = [](const YAML::Node& node) {
    if (node.IsScalar()) return node.Scalar();
    YAML::Emitter out;
    out.SetMapFormat(YAML::Flow);
    out.SetSeqFormat(YAML::Flow);
    out << node;
    return std::string(out.c_str());
  };
  if (key == "do") return v.IsScalar() ? trim(v.Scalar()) : flat(v);
  if (key == "wait") return "wait " + flat(v);
  if (key == "wait_until") return "wait until " + flat(v);
  return key + " " + flat(v);
}

void collect_step_texts(ScenarioFacts& facts, const YAML::Node& list) {
  if (!list || !list.IsSequence()) return;
  for (const auto& item : list) {
    if (item.IsScalar()) {
      facts.step_texts.push_back(trim(item.Scalar()));
    } else if (item.IsMap()) {
      for (const auto& key : kStepKeys) {
        if (item[key]) facts.step_texts.push_back(step_text(item, key));
      }
    }
  }
}

std::vector<Step> read_steps(const ScenarioFacts& facts, const YAML::Node& list,
                             const std::string& key, const std::string& prefix) {
  return StepReader(facts).steps(list, key, prefix);
}

Step read_step(const ScenarioFacts& facts, const YAML::Node& n, const std::string& where,
               const Keys& extra_keys) {
  return StepReader(facts).step(n, where, extra_keys);
}

}  // namespace hil::harness::scenario_parts
