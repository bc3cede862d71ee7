#pragma once
// The arena a simulated car drives in: walls, static obstacles, floor tape
// for the line tracker, RFID tags and the start pose. Loaded from YAML
// (sim/arena_yaml.hpp) or built in (default_warehouse_arena).

#include <string>
#include <variant>
#include <vector>

#include "sim/geometry.hpp"

namespace hil::sim {

/// A rectangle, e.g. a shelf or a parcel.
struct BoxObstacle {
  std::string name;
  Vec2 center_m;
  double width_m = 0;   ///< along the box's own x axis
  double height_m = 0;  ///< along the box's own y axis
  double angle_rad = 0;
};

/// A disc, e.g. a pillar.
struct CircleObstacle {
  std::string name;
  Vec2 center_m;
  double radius_m = 0;
};

using Obstacle = std::variant<BoxObstacle, CircleObstacle>;

/// A strip of floor tape along a polyline; the line tracker sees it.
struct Tape {
  std::string name;
  std::vector<Vec2> points_m;
  double width_m = 0.03;
  bool closed = false;  ///< the last point joins the first

  /// Distance from `p` to the tape's centre line.
  double distance_to_centerline(Vec2 p) const;
  /// True when `p` lies on the tape.
  bool covers(Vec2 p) const;
  /// Centre-line length.
  double length_m() const;
};

/// An RFID tag on the floor; a reader within `radius_m` of it reads `id`.
struct RfidTag {
  std::string id;  ///< e.g. "001", the LOGI station number
  Vec2 position_m;
  double radius_m = 0.05;
};

struct Arena {
  std::string name;
  double width_m = 4.0;
  double height_m = 3.0;
  bool walls = true;  ///< walls along the four edges, outside [0,width]x[0,height]
  double wall_thickness_m = 0.05;
  std::vector<Obstacle> obstacles;
  std::vector<Tape> tapes;
  std::vector<RfidTag> tags;
  Pose start;  ///< where a car is placed when the world is made

  /// True when any tape covers `p`.
  bool on_tape(Vec2 p) const;
  /// The tag whose radius contains `p`, or nullptr.
  const RfidTag* tag_at(Vec2 p) const;
};

/// Problems that make an arena unusable, one sentence each naming the part
/// ("tapes[0]: needs at least 2 points"); empty when the arena is sound.
std::vector<std::string> validate(const Arena& arena);

/// The built-in warehouse (4 m x 3 m, documented in docs/simulation.md): a
/// rounded-rectangle loop of tape with station 001 on its lower straight and
/// 002 on its upper straight, a shelf inside the loop, a pillar 0.4 m beside the
/// tape's left straight, and a start pose on the tape before station 001 heading
/// along the loop (counter-clockwise).
Arena default_warehouse_arena();

}  // namespace hil::sim
