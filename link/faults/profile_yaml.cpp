#include "link/faults/profile_yaml.hpp"

#include "config/yaml.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdint>
#include <set>

namespace hil::link {
namespace {

using protocol::Bytes;

using config::fail_at;

const std::set<std::string, std::less<>> kCommonKeys = {"kind",  "name",       "direction", "from",
                                                        "to",    "match",      "at_frame",  "first",
                                                        "every", "probability"};
const std::set<std::string, std::less<>> kTimeKeys = {"kind", "name", "direction",
                                                      "from", "to",   "at"};

/// Keys a rule of `kind` takes besides the common ones.
std::set<std::string, std::less<>> keys_of(FaultKind kind) {
  std::set<std::string, std::less<>> keys;
  switch (kind) {
    case FaultKind::fragment:
      keys = {"sizes", "gap"};
      break;
    case FaultKind::coalesce:
      keys = {"count", "window"};
      break;
    case FaultKind::corrupt:
      keys = {"target", "field", "bits"};
      break;
    case FaultKind::drop:
      keys = {"unit", "count"};
      break;
    case FaultKind::duplicate:
      keys = {"copies"};
      break;
    case FaultKind::garbage:
      keys = {"length", "hex", "text"};
      break;
    case FaultKind::delay:
      keys = {"delay", "jitter"};
      break;
    case FaultKind::stall:
      keys = {"for", "at"};
      break;
    case FaultKind::disconnect:
    case FaultKind::reset:
      keys = {"at"};
      break;
    case FaultKind::bandwidth:
      // Applies to every write in its window: no frame triggers.
      return {"kind", "name", "direction", "from", "to", "bytes_per_second", "baud"};
    case FaultKind::limit_data:
      return {"kind", "name", "direction", "from", "to", "bytes"};
    case FaultKind::slow_close:
      return {"kind", "name", "direction", "from", "to", "delay"};
    case FaultKind::refuse:
      keys = kTimeKeys;
      keys.insert("for");
      return keys;
  }
  keys.insert(kCommonKeys.begin(), kCommonKeys.end());
  return keys;
}

/// Reads one rule map, reporting every problem at the node it is about.
class RuleReader : config::ItemReader {
 public:
  RuleReader(const std::string& source, const YAML::Node& node, std::size_t index)
      : ItemReader(source, node, "rule " + std::to_string(index), "this kind takes") {}

  FaultRule read() {
    const YAML::Node kind_node = leading("kind");
    const auto kind = parse_fault_kind(scalar(kind_node, "kind"));
    if (!kind) {
      fail_at(source_, kind_node.Mark(),
              prefix_ + ": unknown kind '" + kind_node.Scalar() +
                  "' (known: " + kFaultKindNames.list() + ")");
    }
    prefix_ += " (" + std::string(to_string(*kind)) + ")";
    check_keys(keys_of(*kind));

    FaultRule rule;
    rule.action = make_action(*kind);
    if (auto n = get("name")) rule.name = scalar(*n, "name");
    if (auto n = get("direction")) rule.direction = direction(*n);
    if (auto n = get("from")) rule.window.from = duration(*n, "from");
    if (auto n = get("to")) {
      rule.window.to = duration(*n, "to");
      if (*rule.window.to <= rule.window.from) bad(*n, "'to' must be after 'from'");
    }
    read_trigger(rule.trigger);
    read_action(rule.action);
    if (auto problem = rule_problem(rule)) bad(node_, *problem);
    return rule;
  }

 private:
  ByteCountRange byte_range(const YAML::Node& n, const char* key) {
    const std::string expected =
        "'" + std::string(key) + "' must be [min, max] with 1 <= min <= max, or one number";
    ByteCountRange r;
    if (n.IsScalar()) {
      const auto v = config::parse_whole(n.Scalar());
      if (!v || *v < 1) bad(n, expected);
      r.min = r.max = static_cast<std::size_t>(*v);
      return r;
    }
    if (!n.IsSequence() || n.size() != 2) bad(n, expected);
    std::uint64_t bounds[2] = {0, 0};
    for (std::size_t k = 0; k < 2; ++k) {
      const auto v = n[k].IsScalar() ? config::parse_whole(n[k].Scalar()) : std::nullopt;
      if (!v) bad(n, expected);
      bounds[k] = *v;
    }
    if (bounds[0] < 1 || bounds[0] > bounds[1]) bad(n, expected);
    r.min = static_cast<std::size_t>(bounds[0]);
    r.max = static_cast<std::size_t>(bounds[1]);
    return r;
  }

  DurationRange duration_range(const YAML::Node& n, const char* key) {
    if (n.IsScalar()) {
      const Duration d = duration(n, key);
      return DurationRange{d, d};
    }
    const std::string expected =
        "'" + std::string(key) + "' must be a duration or [min, max] durations with min <= max";
    if (!n.IsSequence() || n.size() != 2) bad(n, expected);
    const DurationRange r{duration(n[0], key), duration(n[1], key)};
    if (r.min > r.max) bad(n, expected);
    return r;
  }

  DirectionFilter direction(const YAML::Node& n) {
    const auto filter = kDirectionFilterNames.parse(scalar(n, "direction"));
    if (!filter) bad(n, "'direction' must be " + kDirectionFilterNames.list(" or "));
    return *filter;
  }

  void read_trigger(Trigger& t) {
    if (auto n = get("match")) t.match = scalar(*n, "match");
    if (auto n = get("at_frame")) t.at_frame = count(*n, "at_frame");
    if (auto n = get("first")) t.first = count(*n, "first");
    if (auto n = get("every")) t.every = count(*n, "every");
    if (auto n = get("at")) t.at = duration(*n, "at");
    if (auto n = get("probability")) {
      const auto p = config::parse_number(scalar(*n, "probability"));
      if (!p || !(*p >= 0.0 && *p <= 1.0)) bad(*n, "'probability' must be a number in [0, 1]");
      t.probability = *p;
    }
  }

  static FaultAction make_action(FaultKind kind) {
    switch (kind) {
      case FaultKind::fragment:
        return Fragment{};
      case FaultKind::coalesce:
        return Coalesce{};
      case FaultKind::corrupt:
        return Corrupt{};
      case FaultKind::drop:
        return Drop{};
      case FaultKind::duplicate:
        return Duplicate{};
      case FaultKind::garbage:
        return Garbage{};
      case FaultKind::delay:
        return Delay{};
      case FaultKind::stall:
        return Stall{};
      case FaultKind::bandwidth:
        return Bandwidth{};
      case FaultKind::disconnect:
        return Disconnect{};
      case FaultKind::reset:
        return Reset{};
      case FaultKind::refuse:
        return Refuse{};
      case FaultKind::limit_data:
        return LimitData{};
      case FaultKind::slow_close:
        break;
    }
    return SlowClose{};
  }

  void read_action(FaultAction& action) {
    std::visit([this](auto& a) { read(a); }, action);
  }

  void read(Fragment& a) {
    if (auto n = get("sizes")) a.piece_bytes = byte_range(*n, "sizes");
    if (auto n = get("gap")) a.gap = duration_range(*n, "gap");
  }
  void read(Coalesce& a) {
    if (auto n = get("count")) a.count = static_cast<std::size_t>(count(*n, "count", 2));
    if (auto n = get("window")) {
      a.window = duration(*n, "window");
      if (a.window <= Duration{0}) bad(*n, "'window' must be a positive duration");
    }
    if (a.count == 0 && a.window == Duration{0})
      bad(node_, "needs 'count' (frames) or 'window' (time)");
  }
  void read(Corrupt& a) {
    if (auto n = get("field")) {
      a.field = scalar(*n, "field");
      a.target = CorruptTarget::field;
    }
    if (auto n = get("target")) {
      const auto target = kCorruptTargetNames.parse(scalar(*n, "target"));
      if (!target) bad(*n, "'target' must be " + kCorruptTargetNames.list(" or "));
      a.target = *target;
      if (a.target == CorruptTarget::field && a.field.empty())
        bad(*n, "target 'field' needs 'field: NAME'");
      if (a.target != CorruptTarget::field && !a.field.empty()) {
        bad(*n, "'field' goes with target 'field' (or leave 'target' out)");
      }
    }
    if (auto n = get("bits")) a.bits = static_cast<std::size_t>(count(*n, "bits"));
  }
  void read(Drop& a) {
    if (auto n = get("unit")) {
      const std::string u = scalar(*n, "unit");
      if (u == "frame") {
        a.unit = DropUnit::frame;
      } else if (u == "bytes") {
        a.unit = DropUnit::bytes;
      } else {
        bad(*n, "'unit' must be frame or bytes");
      }
    }
    if (auto n = get("count")) {
      if (a.unit != DropUnit::bytes) bad(*n, "'count' goes with 'unit: bytes'");
      a.count = byte_range(*n, "count");
    }
  }
  void read(Duplicate& a) {
    if (auto n = get("copies")) a.copies = static_cast<std::size_t>(count(*n, "copies"));
  }
  void read(Garbage& a) {
    const auto hex = get("hex");
    const auto text = get("text");
    const auto length = get("length");
    if ((hex ? 1 : 0) + (text ? 1 : 0) + (length ? 1 : 0) > 1) {
      bad(node_, "give one of 'length' (random bytes), 'hex' or 'text'");
    }
    if (length) a.length = byte_range(*length, "length");
    if (hex) {
      auto bytes = protocol::parse_hex(scalar(*hex, "hex"));
      if (!bytes || bytes->empty()) bad(*hex, "'hex' must be bytes in hex, like \"DE AD BE EF\"");
      a.fixed = std::move(*bytes);
    }
    if (text) {
      a.fixed = protocol::to_bytes(scalar(*text, "text"));
      if (a.fixed.empty()) bad(*text, "'text' must not be empty");
    }
  }
  void read(Delay& a) {
    const auto n = get("delay");
    if (!n) bad(node_, "'delay' is missing (the base delay, like 100ms)");
    a.base = duration(*n, "delay");
    if (auto j = get("jitter")) a.jitter = duration(*j, "jitter");
  }
  void read(Stall& a) { a.duration = required_positive("for"); }
  void read(Refuse& a) { a.duration = required_positive("for"); }
  void read(Bandwidth& a) {
    const auto bps = get("bytes_per_second");
    const auto baud = get("baud");
    if (bps && baud) bad(node_, "give 'bytes_per_second' or 'baud', not both");
    if (!bps && !baud) bad(node_, "needs 'bytes_per_second' or 'baud'");
    if (bps) a.bytes_per_second = count(*bps, "bytes_per_second");
    // A serial byte is 10 bits on the wire (start, 8 data, stop: 8N1).
    if (baud) a.bytes_per_second = std::max<std::uint64_t>(1, count(*baud, "baud", 10) / 10);
  }
  void read(LimitData& a) {
    const auto n = get("bytes");
    if (!n) bad(node_, "'bytes' is missing (how many bytes pass before the link closes)");
    a.bytes = count(*n, "bytes");
  }
  void read(SlowClose& a) {
    const auto n = get("delay");
    if (!n) bad(node_, "'delay' is missing (how long the close is held, like 500ms)");
    a.delay = duration(*n, "delay");
  }
  void read(Disconnect&) {}
  void read(Reset&) {}

  Duration required_positive(const char* key) {
    const auto n = get(key);
    if (!n) bad(node_, "'" + std::string(key) + "' is missing (how long, like 2s)");
    const Duration d = duration(*n, key);
    if (d <= Duration{0}) bad(*n, "'" + std::string(key) + "' must be a positive duration");
    return d;
  }
};

}  // namespace

std::vector<std::string> rule_keys(FaultKind kind) {
  const auto keys = keys_of(kind);
  return {keys.begin(), keys.end()};
}

FaultRule parse_fault_rule(const YAML::Node& node, const std::string& source_name,
                           std::size_t index) {
  return RuleReader(source_name, node, index).read();
}

FaultProfile parse_fault_profile(const YAML::Node& node, const std::string& source_name) {
  YAML::Node rules = node;
  if (!node || node.IsNull()) return {};
  if (node.IsMap()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      const YAML::Node key_node = it->first;
      const std::string key = key_node.IsScalar() ? key_node.Scalar() : std::string{};
      if (key != "rules" && key != "description") {
        fail_at(source_name, key_node.Mark(),
                "unknown key '" + key +
                    "' (a fault profile has 'rules' and an optional 'description')");
      }
    }
    // A const lookup, and reset() rather than operator=: assigning to a
    // YAML::Node that shares `node` rewrites the caller's document (and a
    // missing key then leaves `node` invalid, so Mark() throws).
    const YAML::Node found = static_cast<const YAML::Node&>(node)["rules"];
    if (!found) fail_at(source_name, node.Mark(), "a fault profile needs 'rules: [...]'");
    if (found.IsNull()) return {};
    rules.reset(found);
  }
  if (!rules.IsSequence()) fail_at(source_name, rules.Mark(), "'rules' must be a list of rules");
  FaultProfile profile;
  for (std::size_t i = 0; i < rules.size(); ++i) {
    const YAML::Node rule = static_cast<const YAML::Node&>(rules)[i];
    profile.rules.push_back(RuleReader(source_name, rule, i + 1).read());
  }
  return profile;
}

FaultProfile parse_fault_profile_text(std::string_view yaml, const std::string& source_name) {
  return parse_fault_profile(config::Reader(source_name).parse(yaml), source_name);
}

FaultProfile load_fault_profile(const std::string& path) {
  return parse_fault_profile_text(config::read_file(path, "file"), path);
}

}  // namespace hil::link
