#pragma once
// The physical baseline of the simulation benchmarks: the bodies
// sim::World builds for an arena and a car, made with Box2D alone, so a
// benchmark can step them with no hil code in the loop.

#include <box2d/box2d.h>

#include "sim/arena.hpp"
#include "sim/box2d_shapes.hpp"
#include "sim/geometry.hpp"
#include "sim/mecanum.hpp"

namespace hil::bench {

/// The arena's four walls and its obstacles as static fixtures of one
/// ground body, with the shapes World::build_arena makes.
inline void add_bare_arena(b2World& world, const sim::Arena& arena) {
  b2BodyDef ground_def;
  b2Body* ground = world.CreateBody(&ground_def);
  sim::add_wall_fixtures(*ground, arena);
  for (const auto& obstacle : arena.obstacles)
    sim::add_obstacle_fixture(*ground, obstacle);
}

/// A car's body (its footprint as one box, its mass), awake for good, at
/// `start`.
inline b2Body* add_bare_car(b2World& world, const sim::MecanumDef& car, sim::Pose start) {
  b2BodyDef body_def;
  body_def.type = b2_dynamicBody;
  body_def.position.Set(static_cast<float>(start.x_m), static_cast<float>(start.y_m));
  body_def.angle = static_cast<float>(start.heading_rad);
  body_def.allowSleep = false;
  b2Body* body = world.CreateBody(&body_def);
  b2PolygonShape shape;
  shape.SetAsBox(static_cast<float>(car.length_m / 2), static_cast<float>(car.width_m / 2));
  b2FixtureDef fixture;
  fixture.shape = &shape;
  fixture.density = static_cast<float>(car.mass_kg / (car.length_m * car.width_m));
  fixture.friction = sim::kFixtureFriction;
  body->CreateFixture(&fixture);
  return body;
}

}  // namespace hil::bench
