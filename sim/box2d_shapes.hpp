#pragma once
// The arena's static shapes as Box2D fixtures: its four walls and its
// obstacles, with the friction every fixture of the simulation has. Used by
// World, and by the benchmarks' Box2D-only baseline so both build the same
// bodies.

#include <box2d/box2d.h>

#include <cstdint>
#include <variant>

#include "sim/arena.hpp"
#include "sim/geometry.hpp"

namespace hil::sim {

/// The friction of every fixture of the simulation.
inline constexpr float kFixtureFriction = 0.3f;

/// A box of half-extents `half_width` x `half_height` centred at `center`
/// and turned by `angle_rad`, as a fixture of `body`; `tag` is its user
/// data (0: none).
inline b2Fixture* add_box_fixture(b2Body& body, Vec2 center, double half_width, double half_height,
                                  double angle_rad, std::uintptr_t tag = 0) {
  b2PolygonShape shape;
  shape.SetAsBox(static_cast<float>(half_width), static_cast<float>(half_height),
                 b2Vec2(static_cast<float>(center.x_m), static_cast<float>(center.y_m)),
                 static_cast<float>(angle_rad));
  b2FixtureDef fixture;
  fixture.shape = &shape;
  fixture.friction = kFixtureFriction;
  fixture.userData.pointer = tag;
  return body.CreateFixture(&fixture);
}

/// The arena's four walls, each `wall_thickness_m` thick outside its
/// floor, as fixtures of `ground` tagged `tag`.
inline void add_wall_fixtures(b2Body& ground, const Arena& arena, std::uintptr_t tag = 0) {
  const double t = arena.wall_thickness_m;
  const double w = arena.width_m;
  const double h = arena.height_m;
  add_box_fixture(ground, {w / 2, -t / 2}, w / 2 + t, t / 2, 0, tag);
  add_box_fixture(ground, {w / 2, h + t / 2}, w / 2 + t, t / 2, 0, tag);
  add_box_fixture(ground, {-t / 2, h / 2}, t / 2, h / 2 + t, 0, tag);
  add_box_fixture(ground, {w + t / 2, h / 2}, t / 2, h / 2 + t, 0, tag);
}

/// One obstacle (a box or a circle) as a fixture of `ground` tagged `tag`.
inline b2Fixture* add_obstacle_fixture(b2Body& ground, const Obstacle& obstacle,
                                       std::uintptr_t tag = 0) {
  if (const auto* box = std::get_if<BoxObstacle>(&obstacle))
    return add_box_fixture(ground, box->center_m, box->width_m / 2, box->height_m / 2,
                           box->angle_rad, tag);
  const auto& circle = std::get<CircleObstacle>(obstacle);
  b2CircleShape shape;
  shape.m_p.Set(static_cast<float>(circle.center_m.x_m), static_cast<float>(circle.center_m.y_m));
  shape.m_radius = static_cast<float>(circle.radius_m);
  b2FixtureDef fixture;
  fixture.shape = &shape;
  fixture.friction = kFixtureFriction;
  fixture.userData.pointer = tag;
  return ground.CreateFixture(&fixture);
}

}  // namespace hil::sim
