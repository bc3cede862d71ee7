#pragma once
// The physical baseline of the simulation benchmarks: the bodies
// sim::World builds for an arena and a car, made with Box2D alone, so a
// benchmark can step them with no hil code in the loop.

#include <box2d/box2d.h>

#include <variant>

#include "sim/arena.hpp"
#include "sim/geometry.hpp"
#include "sim/mecanum.hpp"

namespace hil::bench {

/// The arena's four walls and its obstacles as static fixtures of one
/// ground body, as World::build_arena makes them.
inline void add_bare_arena(b2World& world, const sim::Arena& arena) {
  b2BodyDef ground_def;
  b2Body* ground = world.CreateBody(&ground_def);
  auto add_box = [&](double cx, double cy, double hw, double hh, double angle) {
    b2PolygonShape shape;
    shape.SetAsBox(static_cast<float>(hw), static_cast<float>(hh),
                   b2Vec2(static_cast<float>(cx), static_cast<float>(cy)),
                   static_cast<float>(angle));
    b2FixtureDef fixture;
    fixture.shape = &shape;
    fixture.friction = 0.3f;
    ground->CreateFixture(&fixture);
  };
  const double t = arena.wall_thickness_m;
  const double w = arena.width_m;
  const double h = arena.height_m;
  add_box(w / 2, -t / 2, w / 2 + t, t / 2, 0);
  add_box(w / 2, h + t / 2, w / 2 + t, t / 2, 0);
  add_box(-t / 2, h / 2, t / 2, h / 2 + t, 0);
  add_box(w + t / 2, h / 2, t / 2, h / 2 + t, 0);
  for (const auto& obstacle : arena.obstacles) {
    if (const auto* box = std::get_if<sim::BoxObstacle>(&obstacle)) {
      add_box(box->center_m.x_m, box->center_m.y_m, box->width_m / 2, box->height_m / 2,
              box->angle_rad);
    } else {
      const auto& circle = std::get<sim::CircleObstacle>(obstacle);
      b2CircleShape shape;
      shape.m_p.Set(static_cast<float>(circle.center_m.x_m),
                    static_cast<float>(circle.center_m.y_m));
      shape.m_radius = static_cast<float>(circle.radius_m);
      b2FixtureDef fixture;
      fixture.shape = &shape;
      fixture.friction = 0.3f;
      ground->CreateFixture(&fixture);
    }
  }
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
  fixture.friction = 0.3f;
  body->CreateFixture(&fixture);
  return body;
}

}  // namespace hil::bench
