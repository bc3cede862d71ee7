#include "mocks/behaviour_yaml.hpp"

#include <yaml-cpp/yaml.h>

#include <set>

#include "base/enum_names.hpp"
#include "config/yaml.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::mocks {
namespace {

using config::fail_at;

using Keys = std::set<std::string, std::less<>>;

/// "a, b, c", in sorted order.
std::string join(const Keys& keys) {
  return config::join(config::Keys(keys.begin(), keys.end()));
}

const Keys kWhenKeys = {"do", "name", "at", "after", "after_count"};

/// The words of a close behaviour's 'mode'.
constexpr auto kCloseModeWords = base::enum_names<link::CloseMode>(
    {link::CloseMode::graceful, "graceful"}, {link::CloseMode::reset, "reset"});

Keys keys_of(std::string_view action) {
  Keys keys = kWhenKeys;
  if (action == "reject") keys.insert({"match", "times"});
  if (action == "ignore") keys.insert({"match", "times", "for"});
  if (action == "mute-telemetry") keys.insert("for");
  if (action == "send") keys.insert({"text", "hex"});
  if (action == "close") keys.insert("mode");
  return keys;
}

class BehaviourReader : config::ItemReader {
 public:
  BehaviourReader(const std::string& source, const YAML::Node& node, std::size_t index)
      : ItemReader(source, node, "behaviour " + std::to_string(index), "this action takes") {}

  Behaviour read() {
    const YAML::Node action_node = leading("do");
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
        const auto mode = kCloseModeWords.parse(scalar(*n, "mode"));
        if (!mode) bad(*n, "'mode' must be " + kCloseModeWords.list(" or "));
        c.mode = *mode;
      }
      b.action = c;
    }
    return b;
  }
};

}  // namespace

std::vector<Behaviour> parse_behaviours(const YAML::Node& node, const std::string& source_name) {
  YAML::Node list = node;
  if (node.IsMap()) {
    config::Reader(source_name)
        .check_keys(node, {"behaviours", "description"}, "", "a behaviours file takes");
    // A const lookup, and reset() rather than operator=: assigning to a
    // YAML::Node that shares `node` rewrites the caller's document (and a
    // missing key then leaves `node` invalid, so Mark() throws).
    const YAML::Node found = static_cast<const YAML::Node&>(node)["behaviours"];
    if (!found) fail_at(source_name, node.Mark(), "'behaviours' is missing");
    list.reset(found);
  }
  if (list.IsNull()) return {};
  if (!list.IsSequence()) fail_at(source_name, list.Mark(), "'behaviours' must be a list");
  std::vector<Behaviour> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node item = list[i];
    out.push_back(BehaviourReader(source_name, item, i + 1).read());
  }
  return out;
}

std::vector<Behaviour> parse_behaviours_text(std::string_view yaml,
                                             const std::string& source_name) {
  return parse_behaviours(config::Reader(source_name).parse(yaml), source_name);
}

std::vector<Behaviour> load_behaviours(const std::string& path) {
  return parse_behaviours_text(config::read_file(path, "file"), path);
}

}  // namespace hil::mocks
