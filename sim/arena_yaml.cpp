#include "sim/arena_yaml.hpp"

#include "config/yaml.hpp"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

namespace hil::sim {
namespace {

using config::Keys;

using config::describe;
using config::fail_at;
using config::join;
using config::parse_number;

/// Shortest text that reads back to exactly `value`.
std::string format_number(double value) {
  char buffer[64];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  if (ec != std::errc{}) return "0";
  return std::string(buffer, ptr);
}

/// Where each part of the arena came from, so the problems validate() finds
/// after reading can point at the part's node.
struct Marks {
  YAML::Mark document;
  std::map<std::string, std::pair<std::string, YAML::Mark>, std::less<>> parts;

  void add(std::string validate_name, std::string field, const YAML::Mark& mark) {
    parts[std::move(validate_name)] = {std::move(field), mark};
  }
};

/// Reads one map: checks its keys against the allowed ones and hands out
/// values, each with the field path used in messages.
class MapReader {
 public:
  MapReader(const std::string& source, const YAML::Node& node, std::string field,
            const Keys& allowed)
      : source_(source), node_(node), field_(std::move(field)) {
    if (!node_.IsMap()) {
      fail_at(source_, node_.Mark(),
           field_ + ": expected a map with keys " + join(allowed) + ", got " + describe(node_));
    }
    std::set<std::string, std::less<>> seen;
    for (auto it = node_.begin(); it != node_.end(); ++it) {
      // A copy: the iterator hands out a temporary pair, so a reference would dangle.
      const YAML::Node key = it->first;
      const std::string name = key.IsScalar() ? key.Scalar() : std::string{};
      if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
        const std::string shown = describe(key);  // quoted and shortened
        const std::string short_name = key.IsScalar() ? shown.substr(1, shown.size() - 2) : "?";
        fail_at(source_, key.Mark(),
                path(short_name) + ": unknown key " + shown + " (allowed: " + join(allowed) + ")" +
                    config::did_you_mean(name, allowed));
      }
      if (!seen.insert(name).second)
        fail_at(source_, key.Mark(), path(name) + ": key '" + name + "' is given twice");
    }
  }

  std::string path(std::string_view key) const {
    return field_.empty() ? std::string(key) : field_ + "." + std::string(key);
  }

  std::optional<YAML::Node> get(const char* key) const {
    const YAML::Node n = node_[key];
    if (!n) return std::nullopt;
    return n;
  }

  YAML::Node required(const char* key, const std::string& what) const {
    auto n = get(key);
    if (!n) fail_at(source_, node_.Mark(), path(key) + ": missing; expected " + what);
    return *n;
  }

  double number(const YAML::Node& n, const std::string& field, const char* expected) const {
    const auto value = n.IsScalar() ? parse_number(n.Scalar()) : std::nullopt;
    if (!value) fail_at(source_, n.Mark(), field + ": expected " + expected + ", got " + describe(n));
    return *value;
  }

  double any_metres(const char* key) const {
    return number(required(key, "a number of metres"), path(key), "a number of metres");
  }

  double positive_metres(const YAML::Node& n, const std::string& field) const {
    const double value = number(n, field, "a positive number of metres");
    if (!(value > 0)) {
      fail_at(source_, n.Mark(), field + ": expected a positive number of metres, got " + describe(n));
    }
    return value;
  }
  double positive_metres(const char* key) const {
    return positive_metres(required(key, "a positive number of metres"), path(key));
  }
  double optional_positive_metres(const char* key, double fallback) const {
    const auto n = get(key);
    return n ? positive_metres(*n, path(key)) : fallback;
  }

  double optional_radians_from_degrees(const char* key) const {
    const auto n = get(key);
    return n ? deg_to_rad(number(*n, path(key), "a number of degrees")) : 0.0;
  }

  bool optional_bool(const char* key, bool fallback) const {
    const auto n = get(key);
    if (!n) return fallback;
    const std::string text = n->IsScalar() ? n->Scalar() : std::string{};
    if (text == "true" || text == "True" || text == "TRUE") return true;
    if (text == "false" || text == "False" || text == "FALSE") return false;
    fail_at(source_, n->Mark(), path(key) + ": expected true or false, got " + describe(*n));
  }

  std::string text(const YAML::Node& n, const std::string& field, const char* expected) const {
    // The scalar's own text: an unquoted 001 stays "001", not the number 1.
    if (!n.IsScalar())
      fail_at(source_, n.Mark(), field + ": expected " + expected + ", got " + describe(n));
    return n.Scalar();
  }
  std::string optional_text(const char* key) const {
    const auto n = get(key);
    return n ? text(*n, path(key), "a text") : std::string{};
  }

 private:
  const std::string& source_;
  const YAML::Node& node_;
  std::string field_;
};

const Keys kTopKeys = {"name", "obstacles", "size_m", "start", "tags", "tapes", "wall_thickness_m", "walls"};
const Keys kStartKeys = {"heading_deg", "x_m", "y_m"};
const Keys kObstacleKeys = {"box", "circle"};
const Keys kBoxKeys = {"angle_deg", "height_m", "name", "width_m", "x_m", "y_m"};
const Keys kCircleKeys = {"name", "radius_m", "x_m", "y_m"};
const Keys kTapeKeys = {"closed", "name", "points_m", "width_m"};
const Keys kTagKeys = {"id", "radius_m", "x_m", "y_m"};

class ArenaReader {
 public:
  ArenaReader(const YAML::Node& root, const std::string& source) : root_(root), source_(source) {}

  Arena read() {
    if (!root_.IsMap()) {
      fail_at(source_, root_.Mark(),
           "arena: expected a map with keys " + join(kTopKeys) + ", got " + describe(root_));
    }
    marks_.document = root_.Mark();
    const MapReader top(source_, root_, "", kTopKeys);
    Arena arena;
    arena.name = top.get("name") ? top.optional_text("name")
                                 : std::filesystem::path(source_).stem().string();
    read_size(top, arena);
    arena.walls = top.optional_bool("walls", true);
    if (const auto n = top.get("wall_thickness_m")) {
      // Zero is allowed here so an arena without walls round-trips; validate()
      // insists on a positive thickness when there are walls.
      const double t = top.number(*n, "wall_thickness_m", "a number of metres >= 0");
      if (!(t >= 0))
        fail_at(source_, n->Mark(),
             "wall_thickness_m: expected a number of metres >= 0, got " + describe(*n));
      arena.wall_thickness_m = t;
      marks_.add("wall_thickness_m", "wall_thickness_m", n->Mark());
    }
    read_start(top, arena);
    if (const auto n = top.get("obstacles")) {
      each_item(*n, "obstacles",
                [&](const YAML::Node& item, const std::string& field, std::size_t i) {
                  arena.obstacles.push_back(read_obstacle(item, field, i));
                });
    }
    if (const auto n = top.get("tapes")) {
      each_item(*n, "tapes", [&](const YAML::Node& item, const std::string& field, std::size_t i) {
        arena.tapes.push_back(read_tape(item, field, i));
      });
    }
    if (const auto n = top.get("tags")) {
      each_item(*n, "tags", [&](const YAML::Node& item, const std::string& field, std::size_t i) {
        arena.tags.push_back(read_tag(item, field, i));
      });
    }
    report(validate(arena));
    return arena;
  }

 private:
  void read_size(const MapReader& top, Arena& arena) {
    const char* expected = "[width, height] in metres";
    const YAML::Node n = top.required("size_m", expected);
    if (!n.IsSequence() || n.size() != 2)
      fail_at(source_, n.Mark(), std::string("size_m: expected ") + expected + ", got " + describe(n));
    arena.width_m = top.positive_metres(n[0], "size_m[0]");
    arena.height_m = top.positive_metres(n[1], "size_m[1]");
    marks_.add("size", "size_m", n.Mark());
  }

  void read_start(const MapReader& top, Arena& arena) {
    const YAML::Node n = top.required("start", "a map with x_m, y_m and heading_deg");
    const MapReader start(source_, n, "start", kStartKeys);
    arena.start.x_m = start.any_metres("x_m");
    arena.start.y_m = start.any_metres("y_m");
    arena.start.heading_rad = start.optional_radians_from_degrees("heading_deg");
    marks_.add("start", "start", n.Mark());
  }

  template <typename Fn>
  void each_item(const YAML::Node& list, const std::string& field, Fn&& fn) {
    if (list.IsNull()) return;  // "tags:" with nothing after it: no tags
    if (!list.IsSequence())
      fail_at(source_, list.Mark(), field + ": expected a list, got " + describe(list));
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YAML::Node item = list[i];
      fn(item, field + "[" + std::to_string(i) + "]", i);
    }
  }

  Obstacle read_obstacle(const YAML::Node& item, const std::string& field, std::size_t i) {
    const MapReader outer(source_, item, field, kObstacleKeys);
    const auto box = outer.get("box");
    const auto circle = outer.get("circle");
    if (box.has_value() == circle.has_value()) {
      fail_at(source_, item.Mark(),
          field + ": expected exactly one of 'box' or 'circle', got " + (box ? "both" : "neither"));
    }
    const std::string validate_name = "obstacles[" + std::to_string(i) + "]";
    if (box) {
      const MapReader r(source_, *box, outer.path("box"), kBoxKeys);
      BoxObstacle b;
      b.name = r.optional_text("name");
      b.center_m = {r.any_metres("x_m"), r.any_metres("y_m")};
      b.width_m = r.positive_metres("width_m");
      b.height_m = r.positive_metres("height_m");
      b.angle_rad = r.optional_radians_from_degrees("angle_deg");
      marks_.add(validate_name, outer.path("box"), box->Mark());
      return b;
    }
    const MapReader r(source_, *circle, outer.path("circle"), kCircleKeys);
    CircleObstacle c;
    c.name = r.optional_text("name");
    c.center_m = {r.any_metres("x_m"), r.any_metres("y_m")};
    c.radius_m = r.positive_metres("radius_m");
    marks_.add(validate_name, outer.path("circle"), circle->Mark());
    return c;
  }

  Tape read_tape(const YAML::Node& item, const std::string& field, std::size_t i) {
    const MapReader r(source_, item, field, kTapeKeys);
    Tape tape;
    tape.name = r.optional_text("name");
    tape.width_m = r.optional_positive_metres("width_m", tape.width_m);
    tape.closed = r.optional_bool("closed", false);
    const char* expected = "a list of [x, y] points in metres";
    const YAML::Node points = r.required("points_m", expected);
    const std::string points_field = r.path("points_m");
    if (!points.IsSequence())
      fail_at(source_, points.Mark(),
           points_field + ": expected " + expected + ", got " + describe(points));
    const std::string validate_name = "tapes[" + std::to_string(i) + "]";
    for (std::size_t k = 0; k < points.size(); ++k) {
      const YAML::Node p = points[k];
      const std::string point_field = points_field + "[" + std::to_string(k) + "]";
      if (!p.IsSequence() || p.size() != 2) {
        fail_at(source_, p.Mark(),
             point_field + ": expected an [x, y] pair of metres, got " + describe(p));
      }
      tape.points_m.push_back({r.number(p[0], point_field + "[0]", "a number of metres"),
                               r.number(p[1], point_field + "[1]", "a number of metres")});
      marks_.add(validate_name + ".points[" + std::to_string(k) + "]", point_field, p.Mark());
    }
    marks_.add(validate_name, field, item.Mark());
    // Problems with the number of points are best shown at the list.
    marks_.add(validate_name + "/points", points_field, points.Mark());
    return tape;
  }

  RfidTag read_tag(const YAML::Node& item, const std::string& field, std::size_t i) {
    const MapReader r(source_, item, field, kTagKeys);
    RfidTag tag;
    const YAML::Node id = r.required("id", "the tag's id as text, like \"001\"");
    tag.id = r.text(id, r.path("id"), "the tag's id as text, like \"001\"");
    tag.position_m = {r.any_metres("x_m"), r.any_metres("y_m")};
    tag.radius_m = r.optional_positive_metres("radius_m", tag.radius_m);
    const std::string validate_name = "tags[" + std::to_string(i) + "]";
    marks_.add(validate_name, field, item.Mark());
    marks_.add(validate_name + "/id", r.path("id"), id.Mark());
    return tag;
  }

  /// Throws the first of validate()'s problems at the node of the part it names.
  void report(const std::vector<std::string>& problems) {
    if (problems.empty()) return;
    const std::string& problem = problems.front();
    const auto colon = problem.find(": ");
    if (colon == std::string::npos) fail_at(source_, marks_.document, problem);
    const std::string part = problem.substr(0, colon);
    const std::string rest = problem.substr(colon);
    std::string key = part;
    if (part.starts_with("tapes[") && part.find('.') == std::string::npos &&
        rest.find("point") != std::string::npos) {
      key += "/points";
    } else if (part.starts_with("tags[") && rest.find(" id ") != std::string::npos) {
      key += "/id";
    }
    const auto found = marks_.parts.find(key);
    if (found == marks_.parts.end()) fail_at(source_, marks_.document, problem);
    fail_at(source_, found->second.second, found->second.first + rest);
  }

  const YAML::Node& root_;
  const std::string& source_;
  Marks marks_;
};

/// Names and ids are written plain when they read back as the same text,
/// and quoted otherwise ("001" would be fine for us, but not for other tools).
bool plain_safe(const std::string& text) {
  if (text.empty() || text.back() == ' ') return false;
  const unsigned char first = static_cast<unsigned char>(text.front());
  if (!std::isalpha(first)) return false;
  for (const char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (!std::isalnum(u) && c != '_' && c != '-' && c != '.' && c != ' ') return false;
  }
  static const Keys kSpecial = {"null",  "Null",  "NULL", "true", "True", "TRUE", "false",
                                "False", "FALSE", "yes",  "no",   "on",   "off"};
  return std::find(kSpecial.begin(), kSpecial.end(), text) == kSpecial.end();
}

void emit_text(YAML::Emitter& out, const std::string& text) {
  if (plain_safe(text)) {
    out << text;
  } else {
    out << YAML::DoubleQuoted << text;
  }
}

void emit_number(YAML::Emitter& out, double value) {
  out << format_number(value);
}

// One `key: value` of the map being written.
void emit_field(YAML::Emitter& out, const char* key, const std::string& text) {
  out << YAML::Key << key << YAML::Value;
  emit_text(out, text);
}
void emit_field(YAML::Emitter& out, const char* key, double value) {
  out << YAML::Key << key << YAML::Value;
  emit_number(out, value);
}
// A point as the `x_m` and `y_m` of the map being written.
void emit_position(YAML::Emitter& out, Vec2 p) {
  emit_field(out, "x_m", p.x_m);
  emit_field(out, "y_m", p.y_m);
}

}  // namespace

Arena parse_arena(const YAML::Node& node, const std::string& source_name) {
  try {
    return ArenaReader(node, source_name).read();
  } catch (const YAML::Exception& e) {
    // The reader checks every node's type before use; this is a last guard so
    // no input can escape as anything but a ConfigError.
    fail_at(source_name, e.mark, "arena: " + e.msg);
  }
}

Arena parse_arena_text(std::string_view yaml, const std::string& source_name) {
  return parse_arena(config::Reader(source_name).parse(yaml), source_name);
}

Arena load_arena(const std::string& path) {
  return parse_arena_text(config::read_file(path, "file"), path);
}

std::string to_yaml(const Arena& arena) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  emit_field(out, "name", arena.name);
  out << YAML::Key << "size_m" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  emit_number(out, arena.width_m);
  emit_number(out, arena.height_m);
  out << YAML::EndSeq;
  out << YAML::Key << "walls" << YAML::Value << (arena.walls ? "true" : "false");
  emit_field(out, "wall_thickness_m", arena.wall_thickness_m);
  out << YAML::Key << "start" << YAML::Value << YAML::Flow << YAML::BeginMap;
  emit_position(out, arena.start.position());
  emit_field(out, "heading_deg", rad_to_deg(arena.start.heading_rad));
  out << YAML::EndMap;

  // Empty lists are left out: they are optional and read back as empty.
  if (!arena.obstacles.empty()) out << YAML::Key << "obstacles" << YAML::Value << YAML::BeginSeq;
  for (const auto& obstacle : arena.obstacles) {
    out << YAML::BeginMap;
    if (const auto* b = std::get_if<BoxObstacle>(&obstacle)) {
      out << YAML::Key << "box" << YAML::Value << YAML::Flow << YAML::BeginMap;
      emit_field(out, "name", b->name);
      emit_position(out, b->center_m);
      emit_field(out, "width_m", b->width_m);
      emit_field(out, "height_m", b->height_m);
      emit_field(out, "angle_deg", rad_to_deg(b->angle_rad));
      out << YAML::EndMap;
    } else {
      const auto& c = std::get<CircleObstacle>(obstacle);
      out << YAML::Key << "circle" << YAML::Value << YAML::Flow << YAML::BeginMap;
      emit_field(out, "name", c.name);
      emit_position(out, c.center_m);
      emit_field(out, "radius_m", c.radius_m);
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  if (!arena.obstacles.empty()) out << YAML::EndSeq;

  if (!arena.tapes.empty()) out << YAML::Key << "tapes" << YAML::Value << YAML::BeginSeq;
  for (const auto& tape : arena.tapes) {
    out << YAML::BeginMap;
    emit_field(out, "name", tape.name);
    emit_field(out, "width_m", tape.width_m);
    out << YAML::Key << "closed" << YAML::Value << (tape.closed ? "true" : "false");
    out << YAML::Key << "points_m" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const auto& p : tape.points_m) {
      out << YAML::Flow << YAML::BeginSeq;
      emit_number(out, p.x_m);
      emit_number(out, p.y_m);
      out << YAML::EndSeq;
    }
    out << YAML::EndSeq;
    out << YAML::EndMap;
  }
  if (!arena.tapes.empty()) out << YAML::EndSeq;

  if (!arena.tags.empty()) out << YAML::Key << "tags" << YAML::Value << YAML::BeginSeq;
  for (const auto& tag : arena.tags) {
    out << YAML::Flow << YAML::BeginMap;
    // Always quoted: an id like 001 must stay text for every YAML reader.
    out << YAML::Key << "id" << YAML::Value << YAML::DoubleQuoted << tag.id;
    emit_position(out, tag.position_m);
    emit_field(out, "radius_m", tag.radius_m);
    out << YAML::EndMap;
  }
  if (!arena.tags.empty()) out << YAML::EndSeq;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace hil::sim
