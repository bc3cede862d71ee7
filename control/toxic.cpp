#include "control/toxic.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>

#include "config/error.hpp"
#include "config/yaml.hpp"
#include "link/faults/profile_yaml.hpp"

namespace hil::control {
namespace {

using link::Duration;
using link::FaultKind;
using link::Time;
using nlohmann::json;

// ---------------------------------------------------------------- the types

/// One attribute of a Toxiproxy type: a whole number, 0 or more, in `unit`.
struct NumberAttribute {
  std::string_view name;
  std::string_view unit;
};

struct ToxiproxyType {
  std::string_view name;
  std::vector<NumberAttribute> attributes;
};

// The attributes and units of Toxiproxy 2.x's toxics (toxics/*.go in
// Shopify/toxiproxy): every one an integer field, 0 when it is left out.
const std::vector<ToxiproxyType>& toxiproxy_types() {
  static const std::vector<ToxiproxyType> types = {
      {"latency", {{"latency", "milliseconds"}, {"jitter", "milliseconds"}}},
      {"bandwidth", {{"rate", "KB/s, 1 KB = 1000 bytes"}}},
      {"slow_close", {{"delay", "milliseconds"}}},
      {"timeout", {{"timeout", "milliseconds"}}},
      {"reset_peer", {{"timeout", "milliseconds"}}},
      {"slicer",
       {{"average_size", "bytes"}, {"size_variation", "bytes"}, {"delay", "microseconds"}}},
      {"limit_data", {{"bytes", "bytes"}}},
  };
  return types;
}

const ToxiproxyType* toxiproxy_type(std::string_view name) {
  for (const auto& t : toxiproxy_types()) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

bool has_attribute(const ToxiproxyType& type, std::string_view key) {
  return std::any_of(type.attributes.begin(), type.attributes.end(),
                     [key](const NumberAttribute& a) { return a.name == key; });
}

// hil's rule kinds that act on a link (refuse acts on the listener).
constexpr std::array kHilKinds = {
    FaultKind::fragment,  FaultKind::coalesce,   FaultKind::corrupt, FaultKind::drop,
    FaultKind::duplicate, FaultKind::garbage,    FaultKind::delay,   FaultKind::stall,
    FaultKind::bandwidth, FaultKind::disconnect, FaultKind::reset,   FaultKind::limit_data,
    FaultKind::slow_close};

std::optional<FaultKind> hil_kind(std::string_view type) {
  const auto kind = link::parse_fault_kind(type);
  if (!kind || std::find(kHilKinds.begin(), kHilKinds.end(), *kind) == kHilKinds.end())
    return std::nullopt;
  return kind;
}

/// The largest Toxiproxy number hil takes: 10^10 (115 days in ms), far
/// from overflowing nanoseconds or bytes per second.
constexpr std::int64_t kMaxNumber = 10'000'000'000;

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words)
    out += (out.empty() ? "" : ", ") + w;
  return out;
}

std::string json_type(const json& v) {
  if (v.is_null()) return "null";
  if (v.is_boolean()) return "a boolean";
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string";
  if (v.is_array()) return "a list";
  return "an object";
}

[[noreturn]] void bad(const std::string& field, const std::string& what) {
  throw ApiError(400, field + ": " + what);
}

const char* stream_name(link::Direction d) {
  return d == link::Direction::to_car ? "upstream" : "downstream";
}

// ---------------------------------------------------------------- Toxiproxy's attributes

/// Toxiproxy's form of a type that is also a hil kind (bandwidth,
/// slow_close, limit_data) unless an attribute only hil's form has is given.
bool toxiproxy_form(const std::string& type, const json& attributes) {
  const auto* tp = toxiproxy_type(type);
  if (!tp) return false;
  if (!hil_kind(type)) return true;
  for (const auto& [key, value] : attributes.items()) {
    if (!has_attribute(*tp, key)) return false;
    if (type == "slow_close" && value.is_string()) return false;  // a hil duration, "500ms"
  }
  return true;
}

std::int64_t whole_number(const json& v, const std::string& field, std::string_view unit) {
  const std::string expected = "(expected " + std::string(unit) + ", a whole number 0 or more)";
  if (!v.is_number()) bad(field, "got " + json_type(v) + " " + expected);
  if (v.is_number_float()) {
    const double d = v.get<double>();
    if (!std::isfinite(d) || d != std::floor(d)) bad(field, v.dump() + " is not whole " + expected);
    if (d < 0) bad(field, v.dump() + " is negative " + expected);
    if (d > static_cast<double>(kMaxNumber)) bad(field, v.dump() + " is too large " + expected);
    return static_cast<std::int64_t>(d);
  }
  if (v.is_number_integer() && !v.is_number_unsigned() && v.get<std::int64_t>() < 0)
    bad(field, v.dump() + " is negative " + expected);
  if (v.get<std::uint64_t>() > static_cast<std::uint64_t>(kMaxNumber))
    bad(field, v.dump() + " is too large (expected at most " + std::to_string(kMaxNumber) + ")");
  return static_cast<std::int64_t>(v.get<std::uint64_t>());
}

/// Toxiproxy's attributes, checked, with every one left out set to 0.
json toxiproxy_attributes(const ToxiproxyType& type, const json& given) {
  for (const auto& [key, value] : given.items()) {
    if (has_attribute(type, key)) continue;
    std::vector<std::string> names;
    for (const auto& a : type.attributes)
      names.emplace_back(a.name);
    bad("attributes." + key,
        "unknown attribute of a " + std::string(type.name) + " toxic (known: " + join(names) + ")");
  }
  json out = json::object();
  for (const auto& a : type.attributes) {
    const std::string key(a.name);
    out[key] = given.contains(key) ? whole_number(given[key], "attributes." + key, a.unit) : 0;
  }
  return out;
}

// ---------------------------------------------------------------- hil's attributes

enum class Shape : std::uint8_t { text, duration, durations, count, counts, number };

/// What JSON each YAML key of a hil rule takes.
Shape shape_of(std::string_view key) {
  static const std::vector<std::pair<std::string_view, Shape>> shapes = {
      {"match", Shape::text},      {"target", Shape::text},    {"field", Shape::text},
      {"unit", Shape::text},       {"hex", Shape::text},       {"text", Shape::text},
      {"from", Shape::duration},   {"to", Shape::duration},    {"at", Shape::duration},
      {"for", Shape::duration},    {"delay", Shape::duration}, {"jitter", Shape::duration},
      {"window", Shape::duration}, {"gap", Shape::durations},  {"sizes", Shape::counts},
      {"length", Shape::counts},   {"count", Shape::counts},   {"probability", Shape::number},
  };
  for (const auto& [k, s] : shapes) {
    if (k == key) return s;
  }
  return Shape::count;  // at_frame, first, every, copies, bits, bytes_per_second, baud, bytes
}

std::string number_text(const json& v) {
  if (v.is_number_integer()) return v.dump();
  const double d = v.get<double>();
  std::array<char, 512> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), d, std::chars_format::fixed);
  return std::string(buf.data(), r.ptr);
}

/// The value as YAML on one line; throws naming the attribute when its JSON
/// type is wrong for the key.
std::string yaml_value(const std::string& key, const json& v) {
  const std::string field = "attributes." + key;
  const auto scalar = [&](const json& x, bool text) -> std::string {
    if (text && x.is_string()) return x.dump();  // a JSON string is a YAML double-quoted one
    if (!text && x.is_number()) return number_text(x);
    return {};
  };
  switch (shape_of(key)) {
    case Shape::text:
      if (!v.is_string()) bad(field, "got " + json_type(v) + " (expected a string)");
      return v.dump();
    case Shape::duration:
      if (!v.is_string())
        bad(field, "got " + json_type(v) + " (expected a duration with a unit, like \"100ms\")");
      return v.dump();
    case Shape::number:
      if (!v.is_number()) bad(field, "got " + json_type(v) + " (expected a number)");
      return number_text(v);
    case Shape::count:
      if (!v.is_number()) bad(field, "got " + json_type(v) + " (expected a whole number)");
      return number_text(v);
    case Shape::durations:
    case Shape::counts: {
      const bool text = shape_of(key) == Shape::durations;
      const std::string expected =
          text ? "a duration like \"5ms\", or [min, max] durations" : "a number, or [min, max]";
      if (!v.is_array()) {
        const std::string one = scalar(v, text);
        if (one.empty()) bad(field, "got " + json_type(v) + " (expected " + expected + ")");
        return one;
      }
      std::string out = "[";
      for (const auto& x : v) {
        const std::string one = scalar(x, text);
        if (one.empty())
          bad(field, "got a list holding " + json_type(x) + " (expected " + expected + ")");
        out += (out.size() > 1 ? ", " : "") + one;
      }
      return out + "]";
    }
  }
  return v.dump();
}

/// Fails on an attribute a hil kind does not take; for the kinds whose
/// names Toxiproxy's types share, names both forms.
[[noreturn]] void unknown_hil_attribute(FaultKind kind, const std::string& key,
                                        const json& attributes, std::vector<std::string> known) {
  const std::string type(link::to_string(kind));
  const auto* tp = toxiproxy_type(type);
  if (tp && has_attribute(*tp, key)) {
    std::vector<std::string> hil_keys;
    for (const auto& [k, v] : attributes.items()) {
      if (!has_attribute(*tp, k)) hil_keys.push_back(k);
    }
    bad("attributes." + key, "Toxiproxy's '" + key + "' does not go with hil's " + join(hil_keys) +
                                 " (give the attributes of one form)");
  }
  if (tp) {
    std::vector<std::string> all;
    for (const auto& a : tp->attributes)
      all.emplace_back(a.name);
    all.insert(all.end(), known.begin(), known.end());
    known = std::move(all);
  }
  bad("attributes." + key,
      "unknown attribute of a " + type + " toxic (known: " + join(known) + ")");
}

/// The hil rule of a hil-kind toxic, read by the fault profile reader from
/// its attributes; the rule's times as given (the caller shifts them).
/// ConfigErrors become ApiErrors naming the attribute.
link::FaultRule hil_rule(FaultKind kind, link::Direction stream, const json& attributes) {
  const auto keys = link::rule_keys(kind);
  std::vector<std::string> known;
  for (const auto& k : keys) {
    if (k != "kind" && k != "name" && k != "direction") known.push_back(k);
  }
  std::string yaml = "kind: " + std::string(link::to_string(kind)) + "\n";
  yaml += "direction: " + std::string(link::to_string(stream)) + "\n";
  std::vector<std::string> line_keys = {"", ""};  // lines 1 and 2: the whole rule
  for (const auto& [key, value] : attributes.items()) {
    if (key == "direction") {
      bad("attributes.direction",
          "a toxic's direction is its 'stream' (upstream: client to car, downstream: car to "
          "client)");
    }
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      unknown_hil_attribute(kind, key, attributes, known);
    }
    yaml += key + ": " + yaml_value(key, value) + "\n";
    line_keys.push_back(key);
  }
  try {
    const YAML::Node node = config::Reader("attributes").parse(yaml);
    return link::parse_fault_rule(node, "attributes");
  } catch (const config::ConfigError& e) {
    std::string message = e.message();
    // "rule 1 (corrupt): 'bits' must be ..." -> "'bits' must be ..."
    if (message.starts_with("rule ")) {
      if (const auto cut = message.find(": "); cut != std::string::npos)
        message = message.substr(cut + 2);
    }
    const auto line = static_cast<std::size_t>(std::max(e.line(), 0));
    const bool one_key = line >= 1 && line <= line_keys.size() && !line_keys[line - 1].empty();
    bad(one_key ? "attributes." + line_keys[line - 1] : std::string("attributes"), message);
  }
}

// ---------------------------------------------------------------- the body's fields

link::Direction parse_stream(const json& v) {
  if (v.is_string() && v.get<std::string>() == "upstream") return link::Direction::to_car;
  if (v.is_string() && v.get<std::string>() == "downstream") return link::Direction::to_client;
  bad("stream", (v.is_string() ? "'" + v.get<std::string>() + "'" : json_type(v)) +
                    " is not a stream (expected \"upstream\": client to car, or "
                    "\"downstream\": car to client)");
}

double parse_toxicity(const json& v) {
  if (!v.is_number()) bad("toxicity", "got " + json_type(v) + " (expected a number in [0, 1])");
  const double t = v.get<double>();
  if (!(t >= 0.0 && t <= 1.0)) bad("toxicity", v.dump() + " is outside [0, 1]");
  return t;
}

std::string parse_name(const json& v) {
  if (!v.is_string()) bad("name", "got " + json_type(v) + " (expected a string)");
  const auto name = v.get<std::string>();
  if (name.empty()) bad("name", "is empty (expected letters, digits, '_', '.' or '-')");
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '.' || c == '-';
    if (!ok) {
      bad("name", "'" + name.substr(0, 40) +
                      "' holds a character other than letters, digits, "
                      "'_', '.' and '-'");
    }
  }
  return name;
}

std::string parse_type(const json& v) {
  const std::string known = "(known: " + join(toxic_types()) + ")";
  if (!v.is_string()) bad("type", "got " + json_type(v) + " " + known);
  const auto type = v.get<std::string>();
  const auto& types = toxic_types();
  if (std::find(types.begin(), types.end(), type) == types.end())
    bad("type", "unknown type '" + type.substr(0, 40) + "' " + known);
  return type;
}

/// The attributes, checked, in the form the toxic keeps them.
json checked_attributes(const Toxic& toxic, const json& merged) {
  if (toxiproxy_form(toxic.type, merged))
    return toxiproxy_attributes(*toxiproxy_type(toxic.type), merged);
  hil_rule(*hil_kind(toxic.type), toxic.stream, merged);  // throws on a problem
  return merged;
}

// ---------------------------------------------------------------- rules

Duration ms(std::int64_t n) {
  return std::chrono::milliseconds(n);
}

std::int64_t attribute(const Toxic& toxic, const char* key) {
  const auto it = toxic.attributes.find(key);
  return it == toxic.attributes.end() || !it->is_number() ? 0 : it->get<std::int64_t>();
}

link::FaultRule timed(link::FaultAction action, Time at) {
  link::FaultRule r;
  r.action = std::move(action);
  r.trigger.at = at;
  return r;
}

/// The rules of a toxic in Toxiproxy's form; none for one that does
/// nothing (latency 0, bandwidth 0, slow_close 0).
std::vector<link::FaultRule> toxiproxy_rules(const Toxic& toxic, Time start) {
  const std::string& type = toxic.type;
  std::vector<link::FaultRule> rules;
  const auto add = [&](link::FaultAction action) {
    link::FaultRule r;
    r.action = std::move(action);
    rules.push_back(std::move(r));
  };
  if (type == "latency") {
    const auto latency = attribute(toxic, "latency");
    const auto jitter = attribute(toxic, "jitter");
    // Toxiproxy draws latency +/- jitter; hil's delay is base + [0, jitter].
    if (latency != 0 || jitter != 0) {
      add(link::Delay{ms(std::max<std::int64_t>(0, latency - jitter)),
                      ms(jitter > latency ? latency + jitter : 2 * jitter)});
    }
  } else if (type == "bandwidth") {
    const auto rate = attribute(toxic, "rate");
    if (rate > 0) add(link::Bandwidth{static_cast<std::uint64_t>(rate) * 1000});
  } else if (type == "slow_close") {
    const auto delay = attribute(toxic, "delay");
    if (delay > 0) add(link::SlowClose{ms(delay)});
  } else if (type == "timeout") {
    add(link::Drop{});
    const auto timeout = attribute(toxic, "timeout");
    if (timeout > 0) rules.push_back(timed(link::Disconnect{}, start + ms(timeout)));
  } else if (type == "reset_peer") {
    rules.push_back(timed(link::Reset{}, start + ms(attribute(toxic, "timeout"))));
  } else if (type == "slicer") {
    const auto average = attribute(toxic, "average_size");
    const auto variation = attribute(toxic, "size_variation");
    const auto min = static_cast<std::size_t>(std::max<std::int64_t>(1, average - variation));
    const auto max = std::max(min, static_cast<std::size_t>(average + variation));
    const Duration gap = std::chrono::microseconds(attribute(toxic, "delay"));
    add(link::Fragment{{min, max}, {gap, gap}});
  } else if (type == "limit_data") {
    const auto bytes = attribute(toxic, "bytes");
    if (bytes > 0) {
      add(link::LimitData{static_cast<std::uint64_t>(bytes)});
    } else {
      // Toxiproxy closes at the first write, letting none of it through.
      add(link::Drop{});
      link::FaultRule close;
      close.action = link::Disconnect{};
      close.trigger.first = 1;
      rules.push_back(close);
    }
  }
  return rules;
}

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

}  // namespace

const std::vector<std::string>& toxic_types() {
  static const std::vector<std::string> types = [] {
    std::vector<std::string> out;
    for (const auto& t : toxiproxy_types())
      out.emplace_back(t.name);
    for (const auto k : kHilKinds) {
      const std::string name(link::to_string(k));
      if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
    }
    return out;
  }();
  return types;
}

Toxic parse_toxic(const json& body, Time now, const Toxic* existing) {
  if (!body.is_object()) bad("body", "got " + json_type(body) + " (expected a JSON object)");
  for (const auto& [key, value] : body.items()) {
    if (key == "direction") {
      bad("direction",
          "a toxic's direction is its 'stream' (\"upstream\": client to car, "
          "\"downstream\": car to client)");
    }
    if (key != "name" && key != "type" && key != "stream" && key != "toxicity" &&
        key != "attributes") {
      bad(key, "unknown field (expected name, type, stream, toxicity, attributes)");
    }
  }
  Toxic toxic = existing ? *existing : Toxic{};
  if (!existing) toxic.added_at = now;

  if (body.contains("type")) {
    const std::string type = parse_type(body["type"]);
    if (existing && type != existing->type) {
      bad("type", "a toxic's type cannot change (it is " + existing->type +
                      "; delete the toxic and add a new one)");
    }
    toxic.type = type;
  } else if (!existing) {
    bad("type", "missing (known: " + join(toxic_types()) + ")");
  }
  if (body.contains("stream")) toxic.stream = parse_stream(body["stream"]);
  if (body.contains("toxicity")) toxic.toxicity = parse_toxicity(body["toxicity"]);
  if (body.contains("name")) {
    const std::string name = parse_name(body["name"]);
    if (existing && name != existing->name)
      bad("name", "a toxic cannot be renamed (it is " + existing->name + ")");
    toxic.name = name;
  } else if (!existing) {
    toxic.name = toxic.type + "_" + stream_name(toxic.stream);
  }

  json merged = existing ? existing->attributes : json::object();
  if (body.contains("attributes")) {
    const json& given = body["attributes"];
    if (!given.is_object() && !given.is_null())
      bad("attributes", "got " + json_type(given) + " (expected an object)");
    if (given.is_object()) {
      for (const auto& [key, value] : given.items())
        merged[key] = value;
    }
  }
  toxic.attributes = checked_attributes(toxic, merged);
  return toxic;
}

json to_json(const Toxic& toxic) {
  return json{{"name", toxic.name},
              {"type", toxic.type},
              {"stream", stream_name(toxic.stream)},
              {"toxicity", toxic.toxicity},
              {"attributes", toxic.attributes}};
}

bool acts_on_link(const Toxic& toxic, std::uint64_t link_seed) {
  // FNV-1a of the name, mixed with the seed: one draw per (link, toxic).
  std::uint64_t h = 0xCBF29CE484222325ULL;
  for (const char c : toxic.name) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001B3ULL;
  }
  const std::uint64_t x = splitmix64(link_seed ^ splitmix64(h));
  const double draw = static_cast<double>(x >> 11) * 0x1.0p-53;  // [0, 1)
  return draw < toxic.toxicity;
}

link::FaultProfile toxic_rules(const Toxic& toxic, Time link_opened_at) {
  const Time start = std::max(toxic.added_at, link_opened_at);
  std::vector<link::FaultRule> rules;
  if (toxiproxy_form(toxic.type, toxic.attributes)) {
    rules = toxiproxy_rules(toxic, start);
    for (auto& r : rules)
      r.window.from = toxic.added_at;
  } else {
    link::FaultRule r = hil_rule(*hil_kind(toxic.type), toxic.stream, toxic.attributes);
    // Window keys count from when the toxic was added; `at` from when it
    // starts on this link, as Toxiproxy's timed toxics do.
    r.window.from = toxic.added_at + (r.window.from - Time{0});
    if (r.window.to) r.window.to = toxic.added_at + (*r.window.to - Time{0});
    if (r.trigger.at) r.trigger.at = start + (*r.trigger.at - Time{0});
    rules.push_back(std::move(r));
  }
  link::FaultProfile profile;
  for (auto& r : rules) {
    r.name = "toxic:" + toxic.name;
    r.direction = toxic.stream == link::Direction::to_car ? link::DirectionFilter::to_car
                                                          : link::DirectionFilter::to_client;
    profile.rules.push_back(std::move(r));
  }
  return profile;
}

}  // namespace hil::control
