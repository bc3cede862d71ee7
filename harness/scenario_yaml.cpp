#include "harness/scenario_yaml.hpp"

#include "protocol/common/car_profile.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <utility>

#include "client/arduino/operator.hpp"
#include "client/leka/operator.hpp"
#include "client/logi/operator.hpp"
#include "client/wr8/operator.hpp"
#include "client/wr8/svgui_operator.hpp"
#include "harness/reference_client.hpp"
#include "harness/timeline_recorder.hpp"
#include "link/faults/profile_yaml.hpp"
#include "mocks/behaviour_yaml.hpp"
#include "protocol/wr8/profile.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::harness {

namespace fs = std::filesystem;

ScenarioError::ScenarioError(std::string file, int line, int column, const std::string& message)
    : std::runtime_error(
          (line > 0 ? file + ":" + std::to_string(line) + ":" + std::to_string(column) : file) +
          ": " + message),
      file_(std::move(file)),
      line_(line),
      column_(column) {}

namespace {

using Keys = std::vector<std::string>;

std::string join(const Keys& keys) {
  std::string text;
  for (const auto& k : keys)
    text += (text.empty() ? "" : ", ") + k;
  return text;
}

bool contains(const Keys& keys, std::string_view key) {
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

/// The candidate a typo most likely meant, if one is close enough to guess.
std::optional<std::string> closest(std::string_view word, const Keys& candidates) {
  std::optional<std::string> best;
  std::size_t best_distance = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  return best;
}

std::string strip_position(const std::string& what, const std::string& source, int line,
                           int column) {
  const std::string with_position =
      line > 0 ? source + ":" + std::to_string(line) + ":" + std::to_string(column) + ": "
               : source + ": ";
  if (what.starts_with(with_position)) return what.substr(with_position.size());
  return what;
}

std::string car_title(mocks::CarKind car) {
  switch (car) {
    case mocks::CarKind::logi:
      return "LOGI";
    case mocks::CarKind::wr8:
      return "WR8";
    case mocks::CarKind::arduino:
      return "Arduino";
    case mocks::CarKind::leka:
      return "Leka";
  }
  return "car";
}

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
      if (!r.command) return std::pair{1, std::string("an empty action")};
      if (std::holds_alternative<client::arduino::HistoryCommand>(*r.command) ||
          std::holds_alternative<client::arduino::SaveLogCommand>(*r.command) ||
          std::holds_alternative<client::arduino::QuitCommand>(*r.command)) {
        return std::pair{1, "'" + client::arduino::to_text(*r.command) +
                                "' is a command of the interactive prompt, not an operator "
                                "action"};
      }
      return std::nullopt;
    }
    case mocks::CarKind::leka: {
      const auto r = client::leka::parse_operator_line(text);
      if (const auto* e = std::get_if<client::leka::OperatorError>(&r)) {
        return std::pair{static_cast<int>(e->column), e->message};
      }
      if (std::get<client::leka::OperatorLine>(r).kind == client::leka::OperatorLine::Kind::empty) {
        return std::pair{1, std::string("an empty action")};
      }
      return std::nullopt;
    }
  }
  return std::nullopt;
}

std::string trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return std::string(text.substr(first, last - first + 1));
}

std::string format_duration(Duration d) {
  const auto ns = d.count();
  if (ns % 1'000'000'000 == 0) return std::to_string(ns / 1'000'000'000) + "s";
  if (ns % 1'000'000 == 0) return std::to_string(ns / 1'000'000) + "ms";
  if (ns % 1'000 == 0) return std::to_string(ns / 1'000) + "us";
  return std::to_string(ns) + "ns";
}

const Keys kTopKeys = {"name",   "description", "tags",    "car",      "profile",   "reply_latency",
                       "world",  "seed",        "timeout", "settle",   "variables", "faults",
                       "client", "setup",       "steps",   "teardown", "schedule",  "expect"};
const Keys kStepKeys = {"do", "wait", "wait_until", "car", "faults", "obstacle"};
const Keys kMatcherSources = {"wire", "client", "sim", "step", "fault", "car"};
const Keys kWireDirections = {"received", "sent_by_client", "sent_by_car", "received_by_client"};
// "degraded" and "down" are the Arduino link's own states.
const Keys kClientStates = {"connected",    "disconnected", "connecting", "authenticating",
                            "reconnecting", "degraded",     "down"};
// What a wire frame matcher may test besides the frame kind.
const Keys kFrameKeys = {"valid", "error", "text", "hex", "message", "fields"};
/// The names the cars' decoded messages give their fields (docs/scenarios.md,
/// "The timeline"), to catch a misspelt one; a name far from all of them is
/// let through, for a firmware's extra keys and a WR8 profile's own DATA.
Keys known_frame_fields(mocks::CarKind car) {
  switch (car) {
    case mocks::CarKind::logi:
      return {"percent",     "station", "speed_percent", "running",  "mode", "manual",
              "distance_cm", "track",   "deviation",     "obstacle", "rpm"};
    case mocks::CarKind::wr8: {
      Keys names = {"text", "device_code", "device_id",  "state",        "coi",
                    "task", "distance_cm", "angle_deg",  "timestamp_ms", "p",
                    "i",    "d",           "servo_zero", "code",         "unparsed"};
      for (const auto& p : protocol::wr8::Profile::default_data_parameters())
        names.push_back(p.unit.empty() ? p.name : p.name + "_" + p.unit);
      return names;
    }
    case mocks::CarKind::arduino:
      return {"seq", "pwm", "distance_cm", "angle_deg", "info", "code", "text"};
    case mocks::CarKind::leka:
      return {"led", "leds", "rgb", "speed", "left", "right", "id"};
  }
  return {};
}

const Keys kWindowKeys = {"within", "after", "at", "between"};
const Keys kQuantifierKeys = {"never", "count", "at_least", "at_most", "times", "always"};

class Loader {
 public:
  Loader(std::string file, const std::map<std::string, std::string>& overrides,
         const LoadOptions& options)
      : file_(std::move(file)),
        overrides_(overrides),
        allow_outside_paths_(options.allow_outside_paths) {
    dir_ = fs::path(file_).parent_path();
  }

  Scenario load(std::string_view text) {
    YAML::Node root;
    try {
      root = YAML::Load(std::string(text));
    } catch (const YAML::ParserException& e) {
      fail(e.mark, "YAML syntax: " + e.msg);
    } catch (const YAML::Exception& e) {
      fail(e.mark, "YAML: " + e.msg);
    }
    if (!root.IsMap()) {
      fail(root.Mark(),
           "a scenario is a map with at least 'name', 'car' and 'steps' (see docs/scenarios.md)");
    }
    check_keys(root, kTopKeys, "the scenario");
    scenario_.file = file_;

    read_variables(root);
    for (auto it : root) {
      if (it.first.Scalar() != "variables") substitute(it.second);
    }

    const auto name = required(root, "name", "the scenario");
    scenario_.name = scalar(name, "'name'");
    if (trim(scenario_.name).empty()) fail(name, "'name' must not be empty");
    if (auto n = root["description"]) scenario_.description = scalar(n, "'description'");
    if (auto n = root["tags"]) {
      if (!n.IsSequence()) fail(n, "'tags' must be a list of words, like [logi, safety]");
      for (const auto& t : n)
        scenario_.tags.push_back(scalar(t, "a tag"));
    }
    const auto car = required(root, "car", "the scenario");
    const std::string car_text = scalar(car, "'car'");
    const auto kind = mocks::parse_car_kind(car_text);
    if (!kind) {
      const Keys cars = {"logi", "wr8", "arduino", "leka"};
      fail(car, "unknown car '" + car_text + "' (expected logi, wr8, arduino or leka)" +
                    suggestion(car_text, cars));
    }
    scenario_.car = *kind;
    if (auto n = root["profile"]) {
      scenario_.profile = scalar(n, "'profile'");
      if (const auto problem = protocol::car_profile_problem(car_text, scenario_.profile);
          !problem.empty()) {
        fail(n, "'profile': " + problem);
      }
    }
    if (auto n = root["world"]) {
      scenario_.world = existing_file(n, "world file");
    }
    if (auto n = root["seed"]) scenario_.seed = whole(n, "'seed'", 0);
    if (auto n = root["timeout"]) {
      scenario_.timeout = duration(n, "'timeout'");
      if (scenario_.timeout.count() == 0) fail(n, "'timeout' must be more than 0s");
    }
    if (auto n = root["settle"]) scenario_.settle = duration(n, "'settle'");
    if (auto n = root["reply_latency"]) scenario_.reply_latency = duration(n, "'reply_latency'");
    if (auto n = root["faults"]) scenario_.faults = faults(n, "'faults'");
    if (auto n = root["client"]) scenario_.client = client(n);

    // Step texts first: step matchers anywhere refer to them.
    collect_step_texts(root["setup"]);
    collect_step_texts(root["steps"]);
    collect_step_texts(root["teardown"]);
    if (auto n = root["schedule"]; n && n.IsSequence()) {
      for (const auto& item : n) {
        if (item.IsMap()) {
          for (const auto& key : kStepKeys) {
            if (item[key]) step_texts_.push_back(step_text(item, key));
          }
        }
      }
    }

    if (auto n = root["setup"]) scenario_.setup = steps(n, "setup", "setup step ");
    const auto main_steps = required(root, "steps", "the scenario");
    scenario_.steps = steps(main_steps, "steps", "step ");
    if (auto n = root["teardown"]) scenario_.teardown = steps(n, "teardown", "teardown step ");
    if (auto n = root["schedule"]) read_schedule(n);
    if (auto n = root["expect"]) read_expectations(n);
    return std::move(scenario_);
  }

 private:
  // ------------------------------------------------------------ failing

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& message) const {
    const int line = mark.line >= 0 ? mark.line + 1 : 0;
    const int column = mark.column >= 0 ? mark.column + 1 : 0;
    throw ScenarioError(file_, line, column, message);
  }
  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const {
    fail(node.Mark(), message);
  }
  /// At a column inside a one-line scalar (1-based within its text).
  [[noreturn]] void fail_inside(const YAML::Node& node, int column_in_text,
                                const std::string& message) const {
    YAML::Mark mark = node.Mark();
    if (mark.line >= 0 && node.Scalar().find('\n') == std::string::npos) {
      mark.column += column_in_text - 1 + (node.Tag() == "!" ? 1 : 0);
    }
    fail(mark, message);
  }

  static std::string suggestion(std::string_view word, const Keys& candidates) {
    if (auto c = closest(word, candidates)) return "; did you mean '" + *c + "'?";
    return {};
  }

  void check_keys(const YAML::Node& map, const Keys& allowed, const std::string& where) const {
    std::set<std::string> seen;
    for (auto it : map) {
      const YAML::Node& key = it.first;
      if (!key.IsScalar()) fail(key, where + ": keys must be plain words");
      const std::string& k = key.Scalar();
      if (!contains(allowed, k)) {
        fail(key, where + ": unknown key '" + k + "' (allowed: " + join(allowed) + ")" +
                      suggestion(k, allowed));
      }
      if (!seen.insert(k).second) fail(key, where + ": key '" + k + "' is given twice");
    }
  }

  YAML::Node required(const YAML::Node& map, const std::string& key,
                      const std::string& where) const {
    const YAML::Node n = map[key];
    if (!n) fail(map, where + ": '" + key + "' is missing");
    return n;
  }

  // ------------------------------------------------------------- values

  std::string scalar(const YAML::Node& n, const std::string& what) const {
    if (!n.IsScalar()) fail(n, what + " must be a text or a number, not a " + shape(n));
    return n.Scalar();
  }

  static std::string shape(const YAML::Node& n) {
    if (n.IsMap()) return "map";
    if (n.IsSequence()) return "list";
    if (n.IsNull()) return "empty value";
    return "value";
  }

  Duration duration(const YAML::Node& n, const std::string& what) const {
    const std::string text = n.IsScalar() ? n.Scalar() : std::string();
    const auto d = link::parse_duration(text);
    if (!n.IsScalar() || !d) {
      fail(n, what + " must be a duration with a unit (500ms, 2s, 1.5s), got '" + text + "'");
    }
    return *d;
  }

  /// A duration that may be negative ("-100ms"), for anchor offsets.
  Duration signed_duration(const YAML::Node& n, const std::string& what) const {
    if (n.IsScalar() && n.Scalar().starts_with("-")) {
      const auto d = link::parse_duration(std::string_view(n.Scalar()).substr(1));
      if (!d) {
        fail(n, what + " must be a duration with a unit (500ms, -100ms), got '" + n.Scalar() + "'");
      }
      return -*d;
    }
    return duration(n, what);
  }

  std::uint64_t whole(const YAML::Node& n, const std::string& what, std::uint64_t min) const {
    const std::string text = n.IsScalar() ? n.Scalar() : std::string();
    std::uint64_t value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (!n.IsScalar() || text.empty() || ec != std::errc() || end != text.data() + text.size() ||
        value < min) {
      fail(n, what + " must be a whole number >= " + std::to_string(min) + ", got '" + text + "'");
    }
    return value;
  }

  double number(const YAML::Node& n, const std::string& what) const {
    const std::string text = n.IsScalar() ? n.Scalar() : std::string();
    double value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (!n.IsScalar() || text.empty() || ec != std::errc() || end != text.data() + text.size()) {
      fail(n, what + " must be a number, got '" + text + "'");
    }
    return value;
  }

  bool boolean(const YAML::Node& n, const std::string& what) const {
    const std::string text = n.IsScalar() ? n.Scalar() : std::string();
    if (text == "true" || text == "yes" || text == "on") return true;
    if (text == "false" || text == "no" || text == "off") return false;
    fail(n, what + " must be true or false, got '" + text + "'");
  }

  /// A length in metres: a number, or one with a unit (0.3m, 30cm, 300mm).
  double metres(const YAML::Node& n, const std::string& what) const {
    std::string text = n.IsScalar() ? n.Scalar() : std::string();
    double scale = 1.0;
    if (text.ends_with("mm")) {
      scale = 0.001;
      text.resize(text.size() - 2);
    } else if (text.ends_with("cm")) {
      scale = 0.01;
      text.resize(text.size() - 2);
    } else if (text.ends_with("m")) {
      text.resize(text.size() - 1);
    }
    double value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (!n.IsScalar() || text.empty() || ec != std::errc() || end != text.data() + text.size() ||
        value <= 0) {
      fail(n, what + " must be a distance above 0 (0.3m, 30cm, or metres as a number), got '" +
                  (n.IsScalar() ? n.Scalar() : std::string()) + "'");
    }
    return value * scale;
  }

  /// A file named relative to the scenario's folder; it must exist and,
  /// unless allowed, stay inside the scenario's root.
  std::string existing_file(const YAML::Node& n, const std::string& what) const {
    const std::string name = scalar(n, "the " + what);
    if (name.empty()) fail(n, "the " + what + " name must not be empty");
    const bool absolute = fs::path(name).is_absolute();
    const fs::path path = absolute ? fs::path(name) : dir_ / name;
    const auto outside = [&](const std::string& why) {
      fail(n, what + " '" + name + "' " + why + ": a scenario may only name files inside " +
                  scenario_root(file_) +
                  " (its folder's parent); pass --allow-outside-paths to hil run to allow it");
    };
    if (!allow_outside_paths_ && absolute) outside("is an absolute path");
    // Checked by name first, so a ../ escape is refused whether or not the
    // file exists (no probing of the disk from a scenario).
    const fs::path root(scenario_root(file_));
    if (!allow_outside_paths_ && !inside(fs::absolute(path).lexically_normal(), root))
      outside("is outside the scenario's root");
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      fail(n, what + " '" + name + "' does not exist (looked for " + path.string() + ")");
    }
    // A symlink inside the root may point out of it: compare where it
    // really leads with where the root really is.
    const fs::path target = fs::weakly_canonical(path, ec);
    if (!allow_outside_paths_ && !inside(target, fs::weakly_canonical(root, ec)))
      outside("leads outside the scenario's root (to " + target.string() + ")");
    return path.lexically_normal().string();
  }

  static bool inside(const fs::path& resolved, const fs::path& root) {
    const fs::path relative = resolved.lexically_relative(root);
    return !relative.empty() && *relative.begin() != ".." && !relative.is_absolute();
  }

  // ---------------------------------------------------------- variables

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

  void read_variables(const YAML::Node& root) {
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
    for (const auto& [name, value] : overrides_)
      variables_[name] = value;
    scenario_.variables = variables_;
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
                          ")" + suggestion(name, names));
        }
        out += found->second;
        i = close + 1;
        changed = true;
        continue;
      }
      out += text[i++];
    }
    if (changed) {
      substituted_.insert({node.Mark().line, node.Mark().column});
      node = out;
    }
  }

  bool was_substituted(const YAML::Node& n) const {
    return substituted_.contains({n.Mark().line, n.Mark().column});
  }

  // ------------------------------------------------------------- client

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
    for (const auto& s : reference_settings(scenario_.car, scenario_.profile))
      names.push_back(s.name);
    check_keys(n, names, where + " (" + car_title(scenario_.car) + ")");
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
      if (auto problem = reference_setting_problem(scenario_.car, name, value, scenario_.profile)) {
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
                        suggestion(word, kPlaceholders));
      }
    }
  }

  // ------------------------------------------------------------- faults

  link::FaultProfile faults(const YAML::Node& n, const std::string& what) const {
    if (n.IsNull()) return {};
    if (n.IsScalar()) {
      if (n.Scalar() == "off" || n.Scalar() == "none") return {};
      return fault_file(n);
    }
    if (n.IsMap() && n["file"]) {
      check_keys(n, {"file"}, what);
      return fault_file(n["file"]);
    }
    if (n.IsMap() || n.IsSequence()) {
      if (n.IsMap()) check_keys(n, {"rules", "description"}, what);
      try {
        return link::parse_fault_profile(n, file_);
      } catch (const link::FaultProfileError& e) {
        rethrow(e);
      }
    }
    fail(n, what + " must be off, a profile file, {file: FILE}, or {rules: [...]}");
  }

  link::FaultProfile fault_file(const YAML::Node& n) const {
    const std::string path = existing_file(n, "fault profile file");
    try {
      return link::load_fault_profile(path);
    } catch (const link::FaultProfileError& e) {
      rethrow(e);
    }
  }

  [[noreturn]] static void rethrow(const link::FaultProfileError& e) {
    throw ScenarioError(e.source(), e.line(), e.column(),
                        strip_position(e.what(), e.source(), e.line(), e.column()));
  }

  // -------------------------------------------------------------- steps

  /// How a step reads in reports and in the timeline's step records.
  static std::string step_text(const YAML::Node& step, const std::string& key) {
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

  void collect_step_texts(const YAML::Node& list) {
    if (!list || !list.IsSequence()) return;
    for (const auto& item : list) {
      if (item.IsScalar()) {
        step_texts_.push_back(trim(item.Scalar()));
      } else if (item.IsMap()) {
        for (const auto& key : kStepKeys) {
          if (item[key]) step_texts_.push_back(step_text(item, key));
        }
      }
    }
  }

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
    std::string key;
    for (const auto& k : kStepKeys) {
      if (!n[k]) continue;
      if (!key.empty()) {
        fail(n[k], where + ": a step does one thing: '" + key + "' and '" + k + "' are two steps");
      }
      key = k;
    }
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
      w.until = matcher_node(v, where + ": 'wait_until'");
      w.timeout = std::chrono::seconds(10);
      if (auto t = n["timeout"]) w.timeout = duration(t, where + ": 'timeout'");
      s.action = std::move(w);
    } else if (key == "car") {
      s.action = CarStep{behaviour(v, where)};
    } else if (key == "faults") {
      s.action = FaultsStep{faults(v, where + ": 'faults'")};
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
        fail(n, what + usage + ", got '" + n.Scalar() + "'" + suggestion(n.Scalar(), {"fail"}));
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
    if (const auto problem = check_action(scenario_.car, scenario_.profile, text)) {
      const std::string message =
          where + ": " + car_title(scenario_.car) + " action '" + text + "': " + problem->second;
      if (was_substituted(n)) fail(n, message);
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
                    ", or {do: ...} as in docs/mocks.md)" + suggestion(word, kShort));
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
      return mocks::parse_behaviours(list, file_).at(0);
    } catch (const mocks::BehaviourError& e) {
      std::string message = strip_position(e.what(), e.source(), e.line(), e.column());
      if (message.starts_with("behaviour 1 ")) message = "car behaviour " + message.substr(12);
      if (e.line() == 0) fail(n, where + ": " + message);
      throw ScenarioError(e.source(), e.line(), e.column(), where + ": " + message);
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

  // ----------------------------------------------------------- matchers

  static FieldTest test(std::string field, FieldTest::Op op, nlohmann::json value) {
    return FieldTest{std::move(field), op, std::move(value)};
  }

  /// A matcher written alone (wait_until, schedule `when`).
  Matcher matcher_node(const YAML::Node& n, const std::string& where) const {
    if (!n.IsMap()) {
      fail(n, where +
                  " must be a map like {wire: {received: \"MV:STOP\"}}, {client: connected} "
                  "or {sim: at_rest}");
    }
    Keys allowed = kMatcherSources;
    allowed.insert(allowed.end(), kWireDirections.begin(), kWireDirections.end());
    allowed.insert(allowed.end(), kFrameKeys.begin(), kFrameKeys.end());
    if (n["step"]) allowed.push_back("at");
    check_keys(n, allowed, where);
    return matcher(n, where);
  }

  /// Reads the matcher keys of a map whose other keys were checked by the caller.
  Matcher matcher(const YAML::Node& n, const std::string& where) const {
    std::string source;
    for (const auto& k : kMatcherSources) {
      if (!n[k]) continue;
      if (!source.empty()) {
        fail(n[k], where + ": one source per matcher ('" + source + "' and '" + k + "')");
      }
      source = k;
    }
    std::string shorthand;
    for (const auto& k : kWireDirections) {
      if (n[k]) {
        if (!source.empty() || !shorthand.empty()) {
          fail(n[k], where + ": '" + k + "' is a second thing to match");
        }
        shorthand = k;
      }
    }
    if (!shorthand.empty()) return wire_matcher(n, where);
    for (const auto& k : kFrameKeys) {
      if (n[k]) fail(n[k], where + ": '" + k + "' goes with a wire frame key");
    }
    if (source.empty()) {
      fail(n, where + ": nothing to match: give one of " + join(kMatcherSources) + " (or " +
                  join(kWireDirections) + ")");
    }
    if (n["at"] && source != "step" && n["at"].IsScalar() &&
        (n["at"].Scalar() == "start" || n["at"].Scalar() == "end")) {
      fail(n["at"], where + ": 'at: start|end' goes with a step matcher");
    }
    const YAML::Node v = n[source];
    if (source == "wire") return wire(v, where + ": 'wire'");
    if (source == "client") return client_matcher(v, where + ": 'client'");
    if (source == "sim") return sim_matcher(v, where + ": 'sim'");
    if (source == "fault") return fault_matcher(v, where + ": 'fault'");
    if (source == "car") return car_matcher(v, where + ": 'car'");
    std::string phase = "end";
    if (auto at = n["at"];
        at && at.IsScalar() && (at.Scalar() == "start" || at.Scalar() == "end")) {
      phase = at.Scalar();
    }
    return step_matcher(v, phase, where + ": 'step'");
  }

  Matcher wire(const YAML::Node& v, const std::string& where) const {
    if (v.IsScalar()) {
      if (v.Scalar() == "open" || v.Scalar() == "close") {
        Matcher m{Source::wire,
                  v.Scalar(),
                  {},
                  "link " + std::string(v.Scalar() == "open" ? "opened" : "closed")};
        return m;
      }
      fail(v, where + " must be open, close, or a map like {received: \"MV:STOP\"}");
    }
    if (!v.IsMap()) fail(v, where + " must be open, close, or a map like {received: \"MV:STOP\"}");
    Keys allowed = kWireDirections;
    allowed.insert(allowed.end(), kFrameKeys.begin(), kFrameKeys.end());
    allowed.push_back("by");
    check_keys(v, allowed, where);
    if (v["by"])
      fail(v["by"], where + ": 'by' goes with {wire: close} events, write {wire: close}");
    return wire_matcher(v, where);
  }

  /// `n` holds one of the direction keys and maybe valid / error.
  Matcher wire_matcher(const YAML::Node& n, const std::string& where) const {
    std::string key;
    for (const auto& k : kWireDirections) {
      if (!n[k]) continue;
      if (!key.empty()) fail(n[k], where + ": one of " + join(kWireDirections) + ", not two");
      key = k;
    }
    if (key.empty()) fail(n, where + ": give one of " + join(kWireDirections));
    const std::string frame = trim(scalar(n[key], "'" + key + "'"));
    if (frame.empty())
      fail(n[key], "'" + key + "' must be a frame kind (MV:STOP, SP) or * for any");
    Matcher m;
    m.source = Source::wire;
    m.kind = "frame";
    const bool to_car = key == "received" || key == "sent_by_client";
    const bool delivered = key == "received" || key == "received_by_client";
    m.tests.push_back(test("dir", FieldTest::Op::equals, to_car ? "to_car" : "to_client"));
    m.tests.push_back(test("stage", FieldTest::Op::equals, delivered ? "delivered" : "sent"));
    std::optional<bool> valid;
    if (auto v = n["valid"]) valid = boolean(v, "'valid'");
    const std::string what = frame == "*" ? std::string("a frame") : frame;
    // A frame that did not decode is named only as far as the decoder got
    // (a damaged FB:SP may be "FB"), so asking for invalid frames of a kind
    // also counts those whose shorter name the kind starts with.
    const auto kind_op =
        valid == false ? FieldTest::Op::kind_either_prefix : FieldTest::Op::kind_prefix;
    if (frame != "*") m.tests.push_back(test("frame", kind_op, frame));
    if (key == "received") m.text = "car received " + what;
    if (key == "sent_by_client") m.text = "client sent " + what;
    if (key == "sent_by_car") m.text = "car sent " + what;
    if (key == "received_by_client") m.text = "client received " + what;
    if (valid) {
      m.tests.push_back(test("valid", FieldTest::Op::equals, *valid));
      m.text += *valid ? " (valid)" : " (invalid)";
    }
    if (auto error = n["error"]) {
      const std::string e = scalar(error, "'error'");
      // Contains, so "checksum" finds the decoder's "bad_checksum".
      m.tests.push_back(test("error", FieldTest::Op::contains, e));
      m.text += " with error " + e;
    }
    if (auto t = n["text"]) bytes_test(t, "text", where, m);
    if (auto h = n["hex"]) bytes_test(h, "hex", where, m);
    if (auto message = n["message"]) {
      const std::string text = scalar(message, "'message'");
      if (text.empty()) fail(message, where + ": 'message' must not be empty");
      m.tests.push_back(test("message", FieldTest::Op::contains, text));
      m.text += " with message containing '" + text + "'";
    }
    if (auto f = n["fields"]) fields_tests(f, where + ": 'fields'", m);
    return m;
  }

  /// `text: "..."` (the whole frame) or `text: {contains: "..."}`, and the
  /// same for `hex`, whose digits are written as the timeline writes them.
  void bytes_test(const YAML::Node& n, const std::string& key, const std::string& where,
                  Matcher& m) const {
    const std::string what = where + ": '" + key + "'";
    const std::string example = key == "text" ? "\"LOGI:SP:050:D7#\" or {contains: \"SP:050\"}"
                                              : "\"06 01\" or {contains: \"06 01\"}";
    bool whole = true;
    YAML::Node value = n;
    if (n.IsMap()) {
      check_keys(n, {"contains"}, what);
      if (!n["contains"]) fail(n, what + " must be " + example);
      value.reset(n["contains"]);
      whole = false;
    } else if (!n.IsScalar()) {
      fail(n, what + " must be " + example);
    }
    std::string wanted = scalar(value, what);
    if (wanted.empty()) fail(value, what + " must not be empty");
    if (key == "hex") wanted = hex_digits(value, wanted, what);
    m.tests.push_back(test(key, whole ? FieldTest::Op::equals : FieldTest::Op::contains, wanted));
    m.text += " with " + key + (whole ? " " : " containing ") + "'" + wanted + "'";
  }

  /// "0601ff", "06 01 FF" -> "06 01 FF", as the timeline writes bytes.
  std::string hex_digits(const YAML::Node& n, const std::string& text,
                         const std::string& what) const {
    std::string digits;
    for (const char c : text) {
      if (c == ' ' || c == '\t') continue;
      const bool hex = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
      if (!hex) fail(n, what + " must be hex digits like \"06 01 FF\", got '" + text + "'");
      digits += static_cast<char>(c >= 'a' ? c - 'a' + 'A' : c);
    }
    if (digits.size() % 2 != 0) fail(n, what + " must be whole bytes (two hex digits each)");
    std::string out;
    for (std::size_t i = 0; i < digits.size(); i += 2)
      out += (i == 0 ? "" : " ") + digits.substr(i, 2);
    return out;
  }

  /// `fields: {percent: 50, speed_cmps: {at_least: 20, below: 40}, code: BAD_V}`.
  void fields_tests(const YAML::Node& n, const std::string& where, Matcher& m) const {
    if (!n.IsMap() || n.size() == 0) {
      fail(n, where + " must be a map of field names to values, like {percent: 50}");
    }
    static const Keys kOps = {"not", "contains", "below", "above", "at_least", "at_most"};
    std::set<std::string> seen;
    std::string text;
    for (auto it : n) {
      const std::string name = scalar(it.first, "a field name");
      if (name.empty() || name.find('.') != std::string::npos) {
        fail(it.first, where + ": '" + name + "' is not a field name");
      }
      if (!seen.insert(name).second) fail(it.first, where + ": '" + name + "' is given twice");
      if (const Keys known = known_frame_fields(scenario_.car); !contains(known, name)) {
        if (const auto likely = closest(name, known)) {
          fail(it.first, where + ": " + car_title(scenario_.car) + " frames have no field '" +
                             name + "' (they have " + join(known) + "); did you mean '" + *likely +
                             "'?");
        }
      }
      const std::string field = "fields." + name;
      const YAML::Node v = it.second;
      text += (text.empty() ? "" : ", ") + name;
      if (v.IsScalar()) {
        m.tests.push_back(test(field, FieldTest::Op::equals, field_value(v.Scalar())));
        text += " = " + v.Scalar();
        continue;
      }
      if (!v.IsMap() || v.size() == 0) {
        fail(v, where + ": '" + name + "' must be a value (50, BAD_V) or a map with " + join(kOps));
      }
      check_keys(v, kOps, where + ": '" + name + "'");
      for (auto op : v) {
        const std::string k = op.first.Scalar();
        const std::string what = where + ": '" + name + "': '" + k + "'";
        if (k == "not") {
          m.tests.push_back(
              test(field, FieldTest::Op::not_equals, field_value(scalar(op.second, what))));
          text += " not " + op.second.Scalar();
        } else if (k == "contains") {
          m.tests.push_back(test(field, FieldTest::Op::contains, scalar(op.second, what)));
          text += " containing '" + op.second.Scalar() + "'";
        } else {
          const double limit = number(op.second, what);
          const auto op_of = k == "below"      ? FieldTest::Op::less
                             : k == "above"    ? FieldTest::Op::greater
                             : k == "at_least" ? FieldTest::Op::greater_equal
                                               : FieldTest::Op::less_equal;
          m.tests.push_back(test(field, op_of, limit));
          text += (k == "below"      ? " < "
                   : k == "above"    ? " > "
                   : k == "at_least" ? " >= "
                                     : " <= ") +
                  op.second.Scalar();
        }
      }
    }
    m.text += " with " + text;
  }

  Matcher client_matcher(const YAML::Node& v, const std::string& where) const {
    Matcher m;
    m.source = Source::client;
    if (v.IsScalar()) {
      const std::string& word = v.Scalar();
      if (word == "stale" || word == "fresh") {
        m.kind = word;
        m.text =
            word == "stale" ? "client warned of stale telemetry" : "client telemetry fresh again";
        return m;
      }
      if (word == "parse_error") {
        m.kind = word;
        m.text = "client reported a frame it could not parse";
        return m;
      }
      if (!contains(kClientStates, word)) {
        Keys known = kClientStates;
        known.insert(known.end(), {"stale", "fresh", "parse_error"});
        fail(v, where + ": unknown client state '" + word + "' (expected " + join(known) + ")" +
                    suggestion(word, known));
      }
      m.kind = "connection";
      m.tests.push_back(test("state", FieldTest::Op::equals, word));
      m.text = "client " + word;
      return m;
    }
    if (!v.IsMap()) {
      fail(v, where + " must be a state (connected, stale, ...) or a map like {notice: \"text\"}");
    }
    static const Keys kKinds = {"notice",     "command", "exit",     "output",     "action",
                                "connection", "login",   "movement", "parse_error"};
    Keys allowed = kKinds;
    allowed.insert(allowed.end(), {"state", "ok", "reason"});
    check_keys(v, allowed, where);
    std::string kind;
    for (const auto& k : kKinds) {
      if (!v[k]) continue;
      if (!kind.empty()) fail(v[k], where + ": one of " + join(kKinds) + ", not two");
      kind = k;
    }
    if (kind.empty()) fail(v, where + ": give one of " + join(kKinds));
    const auto only = [&](const Keys& extra) {
      for (const char* k : {"state", "ok", "reason"}) {
        if (v[k] && !contains(extra, k)) {
          fail(v[k], where + ": '" + std::string(k) + "' does not go with '" + kind + "'");
        }
      }
    };
    const YAML::Node x = v[kind];
    if (kind == "notice") {
      only({});
      const std::string text = scalar(x, "'notice'");
      m.kind = "notice";
      m.tests.push_back(test("text", FieldTest::Op::contains, text));
      m.text = "client notice containing '" + text + "'";
    } else if (kind == "output") {
      only({});
      const std::string text = scalar(x, "'output'");
      m.kind = "output";
      m.tests.push_back(test("line", FieldTest::Op::contains, text));
      m.text = "client printed a line containing '" + text + "'";
    } else if (kind == "exit") {
      only({});
      m.kind = "exit";
      m.text = "client exited";
      if (!x.IsNull()) {
        const auto code = static_cast<std::int64_t>(whole(x, "'exit'", 0));
        m.tests.push_back(test("code", FieldTest::Op::equals, code));
        m.text += " with " + std::to_string(code);
      }
    } else if (kind == "parse_error") {
      only({});
      const std::string text = scalar(x, "'parse_error'");
      m.kind = "parse_error";
      m.tests.push_back(test("text", FieldTest::Op::contains, text));
      m.text = "client could not parse a frame: '" + text + "'";
    } else if (kind == "movement") {
      only({"reason"});
      const bool enabled = boolean(x, "'movement'");
      m.kind = "movement";
      m.tests.push_back(test("enabled", FieldTest::Op::equals, enabled));
      m.text = enabled ? "client enabled movement" : "client disabled movement";
      if (auto reason = v["reason"]) {
        const std::string r = scalar(reason, "'reason'");
        m.tests.push_back(test("reason", FieldTest::Op::contains, r));
        m.text += " because of '" + r + "'";
      }
    } else if (kind == "login") {
      only({"reason"});
      const bool ok = boolean(x, "'login'");
      m.kind = "login";
      m.tests.push_back(test("ok", FieldTest::Op::equals, ok));
      m.text = ok ? "client logged in" : "client login refused";
      if (auto reason = v["reason"]) {
        const std::string r = scalar(reason, "'reason'");
        m.tests.push_back(test("reason", FieldTest::Op::contains, r));
        m.text += " because of '" + r + "'";
      }
    } else if (kind == "connection") {
      only({});
      const std::string word = scalar(x, "'connection'");
      if (!contains(kClientStates, word)) {
        fail(x, where + ": unknown connection state '" + word + "' (expected " +
                    join(kClientStates) + ")" + suggestion(word, kClientStates));
      }
      m.kind = "connection";
      m.tests.push_back(test("state", FieldTest::Op::equals, word));
      m.text = "client " + word;
    } else if (kind == "command") {
      only({"state"});
      const std::string command = scalar(x, "'command'");
      m.kind = "command";
      m.text = "client command " + command;
      if (command != "*") m.tests.push_back(test("command", FieldTest::Op::kind_prefix, command));
      if (auto state = v["state"]) {
        const std::string s = scalar(state, "'state'");
        m.tests.push_back(test("state", FieldTest::Op::equals, s));
        m.text += " " + s;
      }
    } else {
      only({"ok", "reason"});
      const std::string text = trim(scalar(x, "'action'"));
      m.kind = "action";
      m.text = "action '" + text + "'";
      if (text != "*") m.tests.push_back(test("text", FieldTest::Op::equals, text));
      if (auto ok = v["ok"]) {
        const bool b = boolean(ok, "'ok'");
        m.tests.push_back(test("ok", FieldTest::Op::equals, b));
        m.text += b ? " succeeded" : " failed";
      }
      if (auto reason = v["reason"]) {
        const std::string r = scalar(reason, "'reason'");
        m.tests.push_back(test("reason", FieldTest::Op::contains, r));
        m.text += " because of '" + r + "'";
      }
    }
    return m;
  }

  Matcher sim_matcher(const YAML::Node& v, const std::string& where) const {
    Matcher m;
    m.source = Source::sim;
    static const Keys kWords = {"at_rest", "moving", "collision"};
    if (v.IsScalar()) {
      const std::string& word = v.Scalar();
      if (!contains(kWords, word)) {
        fail(v, where + ": unknown '" + word +
                    "' (expected at_rest, moving, collision, or a map "
                    "with station, speed_below, speed_above, near)" +
                    suggestion(word, kWords));
      }
      m.kind = word;
      m.text = word == "at_rest"  ? "chassis at rest"
               : word == "moving" ? "chassis moving"
                                  : "collision";
      return m;
    }
    if (!v.IsMap()) fail(v, where + " must be at_rest, moving, collision or a map");
    static const Keys kKeys = {"station",     "collision", "speed_below",
                               "speed_above", "near",      "radius"};
    check_keys(v, kKeys, where);
    if (auto s = v["station"]) {
      check_keys(v, {"station"}, where);
      const auto station = whole(s, "'station'", 0);
      m.kind = "station";
      m.tests.push_back(test("station", FieldTest::Op::equals, station));
      m.text = "car reached station " + std::to_string(station);
      return m;
    }
    if (auto c = v["collision"]) {
      check_keys(v, {"collision"}, where);
      const std::string with = scalar(c, "'collision'");
      m.kind = "collision";
      m.tests.push_back(test("with", FieldTest::Op::contains, with));
      m.text = "collision with '" + with + "'";
      return m;
    }
    m.kind = "sample";
    if (auto s = v["speed_below"]) {
      const double speed = number(s, "'speed_below'");
      m.tests.push_back(test("speed_mps", FieldTest::Op::less, speed));
      m.text = "speed below " + s.Scalar() + " m/s";
    }
    if (auto s = v["speed_above"]) {
      const double speed = number(s, "'speed_above'");
      m.tests.push_back(test("speed_mps", FieldTest::Op::greater, speed));
      m.text += std::string(m.text.empty() ? "" : " and ") + "speed above " + s.Scalar() + " m/s";
    }
    if (auto near = v["near"]) {
      if (!near.IsSequence() || near.size() != 2) {
        fail(near, where + ": 'near' must be [x, y] in metres");
      }
      const double x = number(near[0], "x");
      const double y = number(near[1], "y");
      const auto r = v["radius"];
      if (!r) fail(near, where + ": 'near' needs 'radius' (metres)");
      const double radius = number(r, "'radius'");
      if (radius <= 0) fail(r, where + ": 'radius' must be above 0");
      m.tests.push_back(test("x_m", FieldTest::Op::greater_equal, x - radius));
      m.tests.push_back(test("x_m", FieldTest::Op::less_equal, x + radius));
      m.tests.push_back(test("y_m", FieldTest::Op::greater_equal, y - radius));
      m.tests.push_back(test("y_m", FieldTest::Op::less_equal, y + radius));
      m.text += std::string(m.text.empty() ? "" : " and ") + "within " + r.Scalar() + " m of (" +
                near[0].Scalar() + ", " + near[1].Scalar() + ")";
    } else if (auto r = v["radius"]) {
      fail(r, where + ": 'radius' goes with 'near'");
    }
    if (m.tests.empty()) fail(v, where + ": give station, speed_below, speed_above or near");
    return m;
  }

  Matcher fault_matcher(const YAML::Node& v, const std::string& where) const {
    Matcher m;
    m.source = Source::fault;
    if (v.IsScalar()) {
      m.kind = v.Scalar() == "*" ? std::string() : v.Scalar();
      m.text = "fault " + v.Scalar();
      return m;
    }
    if (!v.IsMap()) fail(v, where + " must be a rule kind (drop) or a map {kind, rule, dir}");
    check_keys(v, {"kind", "rule", "dir"}, where);
    m.text = "fault";
    if (auto k = v["kind"]) {
      m.kind = scalar(k, "'kind'");
      m.text += " " + m.kind;
    }
    if (auto r = v["rule"]) {
      const std::string rule = scalar(r, "'rule'");
      m.tests.push_back(test("rule", FieldTest::Op::equals, rule));
      m.text += " by rule '" + rule + "'";
    }
    if (auto d = v["dir"]) {
      const std::string dir = scalar(d, "'dir'");
      if (dir != "to_car" && dir != "to_client")
        fail(d, where + ": 'dir' must be to_car or to_client");
      m.tests.push_back(test("dir", FieldTest::Op::equals, dir));
      m.text += " " + dir;
    }
    return m;
  }

  Matcher car_matcher(const YAML::Node& v, const std::string& where) const {
    Matcher m;
    m.source = Source::car;
    if (v.IsScalar() && v.Scalar() == "fault_state") {
      m.kind = "fault_state";
      m.tests.push_back(test("on", FieldTest::Op::equals, true));
      m.text = "car entered its fault state";
      return m;
    }
    if (!v.IsMap()) {
      fail(v, where + " must be fault_state, {fault_state: false} or {behaviour: NAME}");
    }
    check_keys(v, {"behaviour", "fault_state"}, where);
    if (auto b = v["behaviour"]) {
      if (v["fault_state"]) fail(v["fault_state"], where + ": one of behaviour, fault_state");
      const std::string name = scalar(b, "'behaviour'");
      m.kind = "behaviour";
      if (name != "*") m.tests.push_back(test("name", FieldTest::Op::equals, name));
      m.text = "car behaviour " + name + " fired";
      return m;
    }
    const bool on = boolean(v["fault_state"], "'fault_state'");
    m.kind = "fault_state";
    m.tests.push_back(test("on", FieldTest::Op::equals, on));
    m.text = on ? "car entered its fault state" : "car left its fault state";
    return m;
  }

  Matcher step_matcher(const YAML::Node& v, const std::string& phase,
                       const std::string& where) const {
    std::string wanted;
    std::string chosen_phase = phase;
    if (v.IsMap()) {
      check_keys(v, {"text", "at"}, where);
      if (!v["text"]) fail(v, where + ": 'text' is missing (the step as written, like release)");
      wanted = trim(scalar(v["text"], "'text'"));
      if (auto at = v["at"]) {
        chosen_phase = scalar(at, "'at'");
        if (chosen_phase != "start" && chosen_phase != "end") {
          fail(at, where + ": 'at' must be start or end");
        }
      }
    } else {
      wanted = trim(scalar(v, where));
    }
    const std::string text = resolve_step(v.IsMap() ? v["text"] : v, wanted, where);
    Matcher m;
    m.source = Source::step;
    m.kind = chosen_phase;
    m.tests.push_back(test("text", FieldTest::Op::equals, text));
    m.text = "step '" + text + "' " + (chosen_phase == "start" ? "started" : "ended");
    return m;
  }

  /// The step text `wanted` names: a step's whole text, or the start of
  /// exactly one distinct text (whole words).
  std::string resolve_step(const YAML::Node& at, const std::string& wanted,
                           const std::string& where) const {
    if (contains(step_texts_, wanted)) return wanted;
    std::set<std::string> found;
    for (const auto& t : step_texts_) {
      if (t.starts_with(wanted + " ")) found.insert(t);
    }
    if (found.size() == 1) return *found.begin();
    if (found.size() > 1) {
      fail(at, where + ": '" + wanted + "' starts several steps (" +
                   join(Keys(found.begin(), found.end())) + "); write the whole text");
    }
    fail(at, where + ": no step reads '" + wanted + "' (steps: " + join(step_texts_) + ")" +
                 suggestion(wanted, step_texts_));
  }

  // ------------------------------------------------------------ anchors

  /// An anchor written as a map: matcher keys, occurrence and offset.
  Anchor anchor_map(const YAML::Node& n, const std::string& where, bool allow_times) const {
    if (n.IsScalar()) {
      if (allow_times) {
        if (const auto d = link::parse_duration(n.Scalar())) return Anchor{std::nullopt, 1, *d};
      }
      Anchor a;
      a.event = step_matcher(n, "end", where);
      return a;
    }
    if (!n.IsMap()) fail(n, where + " must be a step's text or a matcher map");
    Keys allowed = kMatcherSources;
    allowed.insert(allowed.end(), kWireDirections.begin(), kWireDirections.end());
    allowed.insert(allowed.end(), kFrameKeys.begin(), kFrameKeys.end());
    allowed.insert(allowed.end(), {"occurrence", "offset"});
    if (n["step"]) allowed.push_back("at");
    check_keys(n, allowed, where);
    Anchor a;
    a.event = matcher(n, where);
    read_occurrence(n, a, where);
    return a;
  }

  void read_occurrence(const YAML::Node& n, Anchor& a, const std::string& where) const {
    if (auto o = n["occurrence"]) {
      if (o.IsScalar() && o.Scalar() == "last") {
        a.occurrence = -1;
      } else {
        const auto count = whole(o, where + ": 'occurrence'", 1);
        if (count > 1'000'000) fail(o, where + ": 'occurrence' is too large");
        a.occurrence = static_cast<int>(count);
      }
    }
    if (auto off = n["offset"]) a.offset = signed_duration(off, where + ": 'offset'");
  }

  // ----------------------------------------------------------- schedule

  void read_schedule(const YAML::Node& list) {
    if (list.IsNull()) return;
    if (!list.IsSequence()) fail(list, "'schedule' must be a list of {at: 5s, <step>} entries");
    std::size_t index = 0;
    for (const auto& item : list) {
      const std::string where = "schedule " + std::to_string(++index);
      if (!item.IsMap()) {
        fail(item, where + ": a scheduled step is a map with 'at' or 'when' and one step key");
      }
      ScheduledStep s;
      Keys allowed = kStepKeys;
      allowed.insert(allowed.end(), {"at", "when", "occurrence", "offset", "timeout", "expect"});
      check_keys(item, allowed, where);
      const auto at = item["at"];
      const auto when = item["when"];
      if (at && when) fail(when, where + ": 'at' and 'when' do not go together");
      if (!at && !when)
        fail(item, where + ": 'at' (a run time like 5s) or 'when' (a matcher) is missing");
      if (at) {
        for (const char* k : {"occurrence", "offset"}) {
          if (item[k]) fail(item[k], where + ": '" + std::string(k) + "' goes with 'when'");
        }
        s.when.offset = duration(at, where + ": 'at'");
      } else {
        s.when = anchor_map(when, where + ": 'when'", false);
        if (when.IsMap()) {
          for (const char* k : {"occurrence", "offset"}) {
            if (item[k] && when[k])
              fail(item[k], where + ": '" + std::string(k) + "' is given twice");
          }
        }
        read_occurrence(item, s.when, where);
      }
      bool has_step = false;
      for (const auto& k : kStepKeys)
        has_step = has_step || item[k];
      if (!has_step) fail(item, where + ": what to do is missing (one of " + join(kStepKeys) + ")");
      if (item["wait"] || item["wait_until"]) {
        fail(item["wait"] ? item["wait"] : item["wait_until"],
             where + ": a scheduled step cannot wait; put waits in 'steps'");
      }
      s.step = step(item, where, {"at", "when", "occurrence", "offset"});
      scenario_.schedule.push_back(std::move(s));
    }
  }

  // ------------------------------------------------------- expectations

  void read_expectations(const YAML::Node& list) {
    if (list.IsNull()) return;
    if (!list.IsSequence()) fail(list, "'expect' must be a list of expectations");
    std::size_t index = 0;
    for (const auto& item : list) {
      scenario_.expectations.push_back(expectation(item, "expectation " + std::to_string(++index)));
    }
  }

  Expectation expectation(const YAML::Node& n, const std::string& where) const {
    if (!n.IsMap()) {
      fail(n, where +
                  ": an expectation is a map like {received: \"MV:STOP\", within: 300ms, after: "
                  "release}");
    }
    Keys allowed = {"label"};
    allowed.insert(allowed.end(), kMatcherSources.begin(), kMatcherSources.end());
    allowed.insert(allowed.end(), kWireDirections.begin(), kWireDirections.end());
    allowed.insert(allowed.end(), kFrameKeys.begin(), kFrameKeys.end());
    allowed.insert(allowed.end(), kWindowKeys.begin(), kWindowKeys.end());
    allowed.insert(allowed.end(), kQuantifierKeys.begin(), kQuantifierKeys.end());
    allowed.insert(allowed.end(), {"tolerance", "only"});
    check_keys(n, allowed, where);

    Expectation e;
    e.line = n.Mark().line + 1;

    // The quantifier.
    std::string quantifier;
    for (const auto& k : kQuantifierKeys) {
      if (!n[k]) continue;
      if (!quantifier.empty()) {
        fail(n[k], where + ": '" + quantifier + "' and '" + k + "' do not go together");
      }
      quantifier = k;
    }
    // Assigning one YAML::Node to another rebinds the data both refer to,
    // so the nested matcher is kept apart instead.
    std::optional<YAML::Node> nested;
    if (quantifier == "never") {
      const auto v = n["never"];
      if (v.IsMap()) {
        nested.emplace(v);
        e.quantifier = Quantifier::never;
      } else if (boolean(v, "'never'")) {
        e.quantifier = Quantifier::never;
      }
    } else if (quantifier == "always") {
      const auto v = n["always"];
      if (v.IsMap()) {
        nested.emplace(v);
      } else if (!boolean(v, "'always'")) {
        fail(v, where + ": write always: true or always: {matcher}");
      }
      e.quantifier = Quantifier::always;
    } else if (quantifier == "count" || quantifier == "at_least" || quantifier == "at_most") {
      e.quantifier = quantifier == "count"      ? Quantifier::exactly
                     : quantifier == "at_least" ? Quantifier::at_least
                                                : Quantifier::at_most;
      e.count = whole(n[quantifier], "'" + quantifier + "'", 0);
    } else if (quantifier == "times") {
      e.quantifier = Quantifier::at_times;
      const auto v = n["times"];
      if (!v.IsSequence() || v.size() == 0) {
        fail(v, where + ": 'times' must be a list of run times like [6s, 8s, 11s]");
      }
      for (const auto& t : v)
        e.times.push_back(duration(t, where + ": 'times'"));
      if (!std::is_sorted(e.times.begin(), e.times.end())) {
        fail(v, where + ": 'times' must be in increasing order");
      }
      if (auto t = n["tolerance"]) e.tolerance = duration(t, where + ": 'tolerance'");
      if (auto o = n["only"]) e.only = boolean(o, "'only'");
    }
    if (quantifier != "times") {
      for (const char* k : {"tolerance", "only"}) {
        if (n[k]) fail(n[k], where + ": '" + std::string(k) + "' goes with 'times'");
      }
    }

    // The matcher.
    if (nested) {
      for (const auto& k : kMatcherSources) {
        if (n[k]) fail(n[k], where + ": the matcher is inside '" + quantifier + "' already");
      }
      for (const auto& k : kWireDirections) {
        if (n[k]) fail(n[k], where + ": the matcher is inside '" + quantifier + "' already");
      }
      e.what = matcher_node(*nested, where + ": '" + quantifier + "'");
    } else {
      e.what = matcher(n, where);
    }

    // The window.
    const auto within = n["within"];
    const auto after = n["after"];
    const auto at = n["at"];
    const auto between = n["between"];
    if (at && n["step"] && at.IsScalar() && (at.Scalar() == "start" || at.Scalar() == "end")) {
      fail(at,
           where +
               ": here 'at' is a run time; for a step's start write step: {text: ..., at: start}");
    }
    if (between) {
      for (const auto& other : {within, after, at}) {
        if (other)
          fail(other,
               where + ": 'between' gives the whole window; drop '" + key_name(n, other) + "'");
      }
      if (!between.IsSequence() || between.size() != 2) {
        fail(between, where + ": 'between' must be [from, to] like [5s, 12s]");
      }
      const Duration from = duration(between[0], where + ": 'between'");
      const Duration to = duration(between[1], where + ": 'between'");
      if (to < from) fail(between, where + ": 'between' must be [from, to] with from <= to");
      e.window.from.offset = from;
      e.window.within = to - from;
    } else if (at) {
      if (after)
        fail(after, where + ": 'at' is a time from the start; it does not go with 'after'");
      e.window.from.offset = duration(at, where + ": 'at'");
      e.window.within = within ? duration(within, where + ": 'within'") : Duration{0};
    } else {
      if (after) e.window.from = anchor_map(after, where + ": 'after'", true);
      if (within) e.window.within = duration(within, where + ": 'within'");
    }

    if (auto label = n["label"]) {
      e.label = scalar(label, "'label'");
    } else {
      e.label = make_label(e);
    }
    return e;
  }

  static std::string key_name(const YAML::Node& map, const YAML::Node& value) {
    for (auto it : map) {
      if (it.second.Mark().line == value.Mark().line &&
          it.second.Mark().column == value.Mark().column) {
        return it.first.Scalar();
      }
    }
    return "?";
  }

  static std::string make_label(const Expectation& e) {
    std::string text;
    switch (e.quantifier) {
      case Quantifier::exists:
        text = e.what.text;
        break;
      case Quantifier::never:
        text = "never: " + e.what.text;
        break;
      case Quantifier::exactly:
        text = "exactly " + std::to_string(e.count) + " x " + e.what.text;
        break;
      case Quantifier::at_least:
        text = "at least " + std::to_string(e.count) + " x " + e.what.text;
        break;
      case Quantifier::at_most:
        text = "at most " + std::to_string(e.count) + " x " + e.what.text;
        break;
      case Quantifier::at_times: {
        std::string times;
        for (const auto t : e.times)
          times += (times.empty() ? "" : ", ") + format_duration(t);
        text = e.what.text + " at " + times + " (+/- " + format_duration(e.tolerance) + ")";
        if (e.only) text += " and no other time";
        break;
      }
      case Quantifier::always:
        text = "always: " + e.what.text;
        break;
    }
    const Anchor& from = e.window.from;
    if (from.event) {
      if (e.window.within) text += " within " + format_duration(*e.window.within);
      text += " after " + from.event->text;
      if (from.occurrence == -1) text += " (the last)";
      if (from.occurrence > 1) text += " (occurrence " + std::to_string(from.occurrence) + ")";
      if (from.offset.count() != 0) text += " + " + format_duration(from.offset);
    } else if (e.window.within) {
      if (from.offset.count() == 0) {
        text += " within " + format_duration(*e.window.within);
      } else if (e.window.within->count() == 0) {
        text += " at " + format_duration(from.offset);
      } else {
        text += " between " + format_duration(from.offset) + " and " +
                format_duration(from.offset + *e.window.within);
      }
    } else if (from.offset.count() != 0) {
      text += " after " + format_duration(from.offset);
    }
    return text;
  }

  std::string file_;
  fs::path dir_;
  std::map<std::string, std::string> overrides_;
  bool allow_outside_paths_ = false;
  std::map<std::string, std::string> variables_;
  std::set<std::pair<int, int>> substituted_;
  Keys step_texts_;
  Scenario scenario_;
};

}  // namespace

std::string scenario_root(const std::string& scenario_file) {
  return fs::absolute(fs::path(scenario_file))
      .lexically_normal()
      .parent_path()
      .parent_path()
      .string();
}

Scenario parse_scenario_text(std::string_view yaml, const std::string& file_name,
                             const std::map<std::string, std::string>& overrides,
                             const LoadOptions& options) {
  return Loader(file_name, overrides, options).load(yaml);
}

Scenario load_scenario(const std::string& path, const std::map<std::string, std::string>& overrides,
                       const LoadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ScenarioError(path, 0, 0, "cannot read the scenario file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ScenarioError(path, 0, 0, "cannot read the scenario file");
  return parse_scenario_text(text.str(), path, overrides, options);
}

}  // namespace hil::harness
