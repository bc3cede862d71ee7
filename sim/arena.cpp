#include "sim/arena.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>

namespace hil::sim {

double Tape::distance_to_centerline(Vec2 p) const {
  if (points_m.empty()) return std::numeric_limits<double>::infinity();
  if (points_m.size() == 1) return length(p - points_m.front());
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < points_m.size(); ++i) {
    best = std::min(best, distance_to_segment(p, points_m[i], points_m[i + 1]));
  }
  if (closed) best = std::min(best, distance_to_segment(p, points_m.back(), points_m.front()));
  return best;
}

double Tape::length_m() const {
  double total = 0;
  for (std::size_t i = 0; i + 1 < points_m.size(); ++i)
    total += length(points_m[i + 1] - points_m[i]);
  if (closed && points_m.size() > 2) total += length(points_m.front() - points_m.back());
  return total;
}

bool Tape::covers(Vec2 p) const {
  // The line tracker asks this four times a step: squared distances, and
  // segments whose box (grown by half the width) misses p skipped outright.
  const double half = width_m / 2;
  const double half2 = half * half;
  const auto near = [&](Vec2 a, Vec2 b) {
    if (p.x_m < std::min(a.x_m, b.x_m) - half || p.x_m > std::max(a.x_m, b.x_m) + half ||
        p.y_m < std::min(a.y_m, b.y_m) - half || p.y_m > std::max(a.y_m, b.y_m) + half)
      return false;
    return distance_squared_to_segment(p, a, b) <= half2;
  };
  if (points_m.size() == 1) return near(points_m[0], points_m[0]);
  for (std::size_t i = 0; i + 1 < points_m.size(); ++i) {
    if (near(points_m[i], points_m[i + 1])) return true;
  }
  return closed && points_m.size() > 2 && near(points_m.back(), points_m.front());
}

bool Arena::on_tape(Vec2 p) const {
  for (const auto& tape : tapes) {
    if (tape.covers(p)) return true;
  }
  return false;
}

const RfidTag* Arena::tag_at(Vec2 p) const {
  // Asked after every step: a tag further than its radius along either axis
  // is further than that in all, so most tags are rejected without hypot.
  for (const auto& tag : tags) {
    const Vec2 d = p - tag.position_m;
    if (std::abs(d.x_m) > tag.radius_m || std::abs(d.y_m) > tag.radius_m) continue;
    if (length(d) <= tag.radius_m) return &tag;
  }
  return nullptr;
}

namespace {

bool inside(const Arena& arena, Vec2 p) {
  return p.x_m >= 0 && p.x_m <= arena.width_m && p.y_m >= 0 && p.y_m <= arena.height_m;
}

bool finite(Vec2 p) {
  return std::isfinite(p.x_m) && std::isfinite(p.y_m);
}

}  // namespace

std::vector<std::string> validate(const Arena& arena) {
  std::vector<std::string> problems;
  auto add = [&](std::string text) { problems.push_back(std::move(text)); };
  if (!(arena.width_m > 0) || !(arena.height_m > 0) || !std::isfinite(arena.width_m) ||
      !std::isfinite(arena.height_m)) {
    add("size: width and height must be positive numbers of metres");
    return problems;
  }
  if (arena.width_m > 1000 || arena.height_m > 1000) add("size: at most 1000 m a side");
  if (arena.walls && !(arena.wall_thickness_m > 0)) add("wall_thickness_m: must be positive");
  for (std::size_t i = 0; i < arena.obstacles.size(); ++i) {
    const std::string where = "obstacles[" + std::to_string(i) + "]";
    std::visit(
        [&](const auto& o) {
          using T = std::decay_t<decltype(o)>;
          if (!finite(o.center_m) || !inside(arena, o.center_m))
            add(where + ": centre lies outside the arena");
          if constexpr (std::is_same_v<T, BoxObstacle>) {
            if (!(o.width_m > 0) || !(o.height_m > 0))
              add(where + ": box width and height must be positive");
          } else {
            if (!(o.radius_m > 0)) add(where + ": circle radius must be positive");
          }
        },
        arena.obstacles[i]);
  }
  for (std::size_t i = 0; i < arena.tapes.size(); ++i) {
    const std::string where = "tapes[" + std::to_string(i) + "]";
    const auto& tape = arena.tapes[i];
    if (tape.points_m.size() < 2) add(where + ": needs at least 2 points");
    if (tape.closed && tape.points_m.size() < 3) add(where + ": a closed tape needs 3 points");
    if (!(tape.width_m > 0)) add(where + ": width must be positive");
    for (std::size_t k = 0; k < tape.points_m.size(); ++k) {
      if (!finite(tape.points_m[k]) || !inside(arena, tape.points_m[k]))
        add(where + ".points[" + std::to_string(k) + "]: lies outside the arena");
    }
  }
  std::set<std::string> ids;
  for (std::size_t i = 0; i < arena.tags.size(); ++i) {
    const std::string where = "tags[" + std::to_string(i) + "]";
    const auto& tag = arena.tags[i];
    if (tag.id.empty()) add(where + ": id must not be empty");
    if (!ids.insert(tag.id).second) add(where + ": id '" + tag.id + "' is used twice");
    if (!finite(tag.position_m) || !inside(arena, tag.position_m))
      add(where + ": lies outside the arena");
    if (!(tag.radius_m > 0)) add(where + ": radius must be positive");
  }
  if (!finite(arena.start.position()) || !inside(arena, arena.start.position()) ||
      !std::isfinite(arena.start.heading_rad))
    add("start: lies outside the arena");
  return problems;
}

namespace {

/// Rounded rectangle [x0,x1]x[y0,y1] with corner radius r, counter-clockwise
/// from the end of the lower straight, `per_corner` segments per bend.
std::vector<Vec2> rounded_loop(double x0, double y0, double x1, double y1, double r,
                               int per_corner) {
  std::vector<Vec2> points;
  const Vec2 centres[4] = {{x1 - r, y0 + r}, {x1 - r, y1 - r}, {x0 + r, y1 - r}, {x0 + r, y0 + r}};
  const double start_angle[4] = {-std::numbers::pi / 2, 0, std::numbers::pi / 2, std::numbers::pi};
  for (int c = 0; c < 4; ++c) {
    for (int k = 0; k <= per_corner; ++k) {
      const double a = start_angle[c] + (std::numbers::pi / 2) * k / per_corner;
      points.push_back({centres[c].x_m + r * std::cos(a), centres[c].y_m + r * std::sin(a)});
    }
  }
  return points;
}

}  // namespace

Arena default_warehouse_arena() {
  Arena arena;
  arena.name = "warehouse";
  arena.width_m = 4.0;
  arena.height_m = 3.0;
  arena.walls = true;
  arena.wall_thickness_m = 0.05;
  arena.obstacles.push_back(BoxObstacle{"shelf", {2.0, 1.5}, 1.2, 0.5, 0});
  arena.obstacles.push_back(CircleObstacle{"pillar", {0.3, 2.0}, 0.1});
  Tape loop;
  loop.name = "loop";
  loop.width_m = 0.03;
  loop.closed = true;
  loop.points_m = rounded_loop(0.8, 0.6, 3.2, 2.4, 0.4, 6);
  // Round to the millimetre so the built-in arena and its YAML copy agree.
  for (auto& p : loop.points_m) {
    p.x_m = std::round(p.x_m * 1000) / 1000;
    p.y_m = std::round(p.y_m * 1000) / 1000;
  }
  arena.tapes.push_back(std::move(loop));
  arena.tags.push_back(RfidTag{"001", {2.0, 0.6}, 0.05});
  arena.tags.push_back(RfidTag{"002", {2.0, 2.4}, 0.05});
  arena.start = Pose{1.2, 0.6, 0.0};
  return arena;
}

}  // namespace hil::sim
