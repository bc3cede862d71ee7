#include "mocks/behaviour_yaml.hpp"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <fstream>
#include <set>
#include <sstream>

#include "link/faults/profile_yaml.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::mocks {
namespace {

[[noreturn]] void fail(const std::string& source, const YAML::Mark& mark,
                       const std::string& message) {
  const int line = mark.line >= 0 ? mark.line + 1 : 0;
  const int column = mark.column >= 0 ? mark.column + 1 : 0;
  throw BehaviourError(source, line, column, message);
}

using Keys = std::set<std::string, std::less<>>;

const Keys kWhenKeys = {"do", "name", "at", "after", "after_count"};

Keys keys_of(std::string_view action) {
  Keys keys = kWhenKeys;
  if (action == "reject") keys.insert({"match", "times"});
  if (action == "ignore") keys.insert({"match", "times", "for"});
  if (action == "mute-telemetry") keys.insert("for");
  if (action == "send") keys.insert({"text", "hex"});
  if (action == "close") keys.insert("mode");
  return keys;
}

std::string join(const Keys& keys) {
  std::string text;
  for (const auto& k : keys)
    text += (text.empty() ? "" : ", ") + k;
  return text;
}

class BehaviourReader {
 public:
  BehaviourReader(const std::string& source, const YAML::Node& node, std::size_t index)
      : source_(source), node_(node), prefix_("behaviour " + std::to_string(index)) {}

  Behaviour read() {
    if (!node_.IsMap()) bad(node_, "must be a map with at least 'do'");
    const YAML::Node action_node = node_["do"];
    if (!action_node) bad(node_, "'do' is missing");
    const std::string action = scalar(action_node, "do");
    static const Keys kActions = {"reject", "ignore",      "mute-telemetry", "send",
                                  "fault",  "clear-fault", "close"};
    if (!kActions.contains(action)) {
      bad(action_node, "unknown action '" + action + "' (known: " + join(kActions) + ")");
    }
    prefix_ += " (" + action + ")";
    check_keys(keys_of(action));

    Behaviour b;
    if (auto n = get("name")) b.name = scalar(*n, "name");
    if (auto n = get("at")) b.when.at = duration(*n, "at");
    if (auto n = get("after")) b.when.after_frame = scalar(*n, "after");
    if (auto n = get("after_count")) {
      if (b.when.after_frame.empty()) bad(*n, "'after_count' needs 'after' (a frame kind)");
      b.when.after_count = count(*n, "after_count");
    }
    if (action == "reject") {
      Reject r;
      if (auto n = get("match")) r.match = scalar(*n, "match");
      if (auto n = get("times")) r.count = count(*n, "times");
      b.action = r;
    } else if (action == "ignore") {
      Ignore i;
      if (auto n = get("match")) i.match = scalar(*n, "match");
      if (auto n = get("times")) i.count = count(*n, "times");
      if (auto n = get("for")) i.duration = duration(*n, "for");
      b.action = i;
    } else if (action == "mute-telemetry") {
      const auto n = get("for");
      if (!n) bad(node_, "'for' is missing (how long telemetry stops, like 3s)");
      b.action = MuteTelemetry{duration(*n, "for")};
    } else if (action == "send") {
      const auto text = get("text");
      const auto hex = get("hex");
      if ((text ? 1 : 0) + (hex ? 1 : 0) != 1) bad(node_, "give one of 'text' or 'hex'");
      SendBytes s;
      if (text) {
        const std::string t = scalar(*text, "text");
        if (t.empty()) bad(*text, "'text' must not be empty");
        s.bytes.assign(t.begin(), t.end());
      } else {
        auto bytes = protocol::parse_hex(scalar(*hex, "hex"));
        if (!bytes || bytes->empty()) bad(*hex, "'hex' must be bytes in hex, like \"2A 2B 2C 2D\"");
        s.bytes = std::move(*bytes);
      }
      b.action = std::move(s);
    } else if (action == "fault") {
      b.action = EnterFault{};
    } else if (action == "clear-fault") {
      b.action = ClearFault{};
    } else {
      CloseConnection c;
      if (auto n = get("mode")) {
        const std::string mode = scalar(*n, "mode");
        if (mode == "graceful") {
          c.mode = link::CloseMode::graceful;
        } else if (mode == "reset") {
          c.mode = link::CloseMode::reset;
        } else {
          bad(*n, "'mode' must be graceful or reset");
        }
      }
      b.action = c;
    }
    return b;
  }

 private:
  std::optional<YAML::Node> get(const char* key) const {
    YAML::Node n = node_[key];
    if (!n) return std::nullopt;
    return n;
  }

  void check_keys(const Keys& allowed) {
    Keys seen;
    for (auto it = node_.begin(); it != node_.end(); ++it) {
      const YAML::Node key = it->first;
      const std::string name = key.IsScalar() ? key.Scalar() : std::string{};
      if (!allowed.contains(name)) {
        fail(source_, key.Mark(),
             prefix_ + ": unknown key '" + name + "' (this action takes: " + join(allowed) + ")");
      }
      if (!seen.insert(name).second)
        fail(source_, key.Mark(), prefix_ + ": key '" + name + "' given twice");
    }
  }

  [[noreturn]] void bad(const YAML::Node& n, const std::string& what) {
    fail(source_, n.Mark(), prefix_ + ": " + what);
  }

  std::string scalar(const YAML::Node& n, const char* key) {
    if (!n.IsScalar()) bad(n, "'" + std::string(key) + "' must be a single value");
    return n.Scalar();
  }

  std::uint64_t count(const YAML::Node& n, const char* key) {
    const std::string text = scalar(n, key);
    std::uint64_t v = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc{} || ptr != text.data() + text.size() || text.empty() || v < 1)
      bad(n, "'" + std::string(key) + "' must be a whole number >= 1");
    return v;
  }

  Duration duration(const YAML::Node& n, const char* key) {
    const auto d = link::parse_duration(scalar(n, key));
    if (!d) {
      bad(n, "'" + std::string(key) +
                 "' must be a duration with a unit, like 250ms or 1.5s (units: ns, us, ms, s)");
    }
    return *d;
  }

  const std::string& source_;
  const YAML::Node& node_;
  std::string prefix_;
};

}  // namespace

BehaviourError::BehaviourError(std::string source, int line, int column, const std::string& message)
    : std::runtime_error(
          (line > 0 ? source + ":" + std::to_string(line) + ":" + std::to_string(column) : source) +
          ": " + message),
      source_(std::move(source)),
      line_(line),
      column_(column) {}

std::vector<Behaviour> parse_behaviours(const YAML::Node& node, const std::string& source_name) {
  YAML::Node list = node;
  if (node.IsMap()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      const YAML::Node key = it->first;
      const std::string name = key.IsScalar() ? key.Scalar() : std::string{};
      if (name != "behaviours" && name != "description") {
        fail(source_name, key.Mark(),
             "unknown key '" + name + "' (a behaviours file takes: behaviours, description)");
      }
    }
    // A const lookup, and reset() rather than operator=: assigning to a
    // YAML::Node that shares `node` rewrites the caller's document (and a
    // missing key then leaves `node` invalid, so Mark() throws).
    const YAML::Node found = static_cast<const YAML::Node&>(node)["behaviours"];
    if (!found) fail(source_name, node.Mark(), "'behaviours' is missing");
    list.reset(found);
  }
  if (list.IsNull()) return {};
  if (!list.IsSequence()) fail(source_name, list.Mark(), "'behaviours' must be a list");
  std::vector<Behaviour> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node item = list[i];
    out.push_back(BehaviourReader(source_name, item, i + 1).read());
  }
  return out;
}

std::vector<Behaviour> parse_behaviours_text(std::string_view yaml,
                                             const std::string& source_name) {
  YAML::Node node;
  try {
    node = YAML::Load(std::string(yaml));
  } catch (const YAML::ParserException& e) {
    fail(source_name, e.mark, "not valid YAML: " + e.msg);
  }
  return parse_behaviours(node, source_name);
}

std::vector<Behaviour> load_behaviours(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BehaviourError(path, 0, 0, "cannot read the file");
  std::stringstream text;
  text << in.rdbuf();
  return parse_behaviours_text(text.str(), path);
}

}  // namespace hil::mocks
