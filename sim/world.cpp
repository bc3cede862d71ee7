#include "sim/world.hpp"

#include <box2d/box2d.h>

#include <stdexcept>

#include "sim/box2d_shapes.hpp"
#include "sim/fixture_tag.hpp"

namespace hil::sim {

using detail::fixture_index;
using detail::fixture_kind;
using detail::fixture_tag;
using detail::FixtureKind;

class World::ContactListener final : public b2ContactListener {
 public:
  explicit ContactListener(World& world) : world_(world) {}
  void BeginContact(b2Contact* contact) override { report(contact, ContactEvent::Phase::begin); }
  void EndContact(b2Contact* contact) override { report(contact, ContactEvent::Phase::end); }

 private:
  void report(b2Contact* contact, ContactEvent::Phase phase) {
    const std::uintptr_t a = contact->GetFixtureA()->GetUserData().pointer;
    const std::uintptr_t b = contact->GetFixtureB()->GetUserData().pointer;
    Vec2 point;
    if (phase == ContactEvent::Phase::begin) {
      b2WorldManifold manifold;
      contact->GetWorldManifold(&manifold);
      if (contact->GetManifold()->pointCount > 0)
        point = {static_cast<double>(manifold.points[0].x),
                 static_cast<double>(manifold.points[0].y)};
    }
    one_side(a, b, phase, point);
    one_side(b, a, phase, point);
  }

  void one_side(std::uintptr_t self, std::uintptr_t other, ContactEvent::Phase phase, Vec2 point) {
    if (fixture_kind(self) != FixtureKind::vehicle) return;
    const std::size_t index = fixture_index(self);
    Vehicle& vehicle = *world_.vehicles_.at(index);
    ContactEvent event;
    event.time = step_end(world_.steps_ + 1);
    event.vehicle = index;
    event.phase = phase;
    event.other = fixture_index(other);
    switch (fixture_kind(other)) {
      case FixtureKind::obstacle:
        event.with = ContactEvent::With::obstacle;
        event.other_name = std::visit([](const auto& o) { return o.name; },
                                      world_.def_.arena.obstacles.at(event.other));
        break;
      case FixtureKind::vehicle:
        event.with = ContactEvent::With::vehicle;
        event.other_name = world_.vehicles_.at(event.other)->name();
        break;
      default:
        event.with = ContactEvent::With::wall;
        event.other = 0;
        event.other_name = "wall";
        break;
    }
    event.point_m = phase == ContactEvent::Phase::begin ? point : vehicle.pose().position();
    vehicle.contacts_ += phase == ContactEvent::Phase::begin ? 1 : -1;
    world_.contacts_.push_back(std::move(event));
  }

  World& world_;
};

World::World(WorldDef def) : def_(std::move(def)) {
  const auto problems = validate(def_.arena);
  if (!problems.empty()) {
    std::string text = "arena '" + def_.arena.name + "' is unusable:";
    for (const auto& p : problems)
      text += "\n  " + p;
    throw std::invalid_argument(text);
  }
  b2_ = std::make_unique<b2World>(b2Vec2(0.0f, 0.0f));  // seen from above: no gravity
  listener_ = std::make_unique<ContactListener>(*this);
  b2_->SetContactListener(listener_.get());
  build_arena();
}

World::~World() {
  // Destroying a touching body reports EndContact; nobody is listening now.
  b2_->SetContactListener(nullptr);
  vehicles_.clear();
}

void World::build_arena() {
  b2BodyDef body_def;  // static, at the origin
  ground_ = b2_->CreateBody(&body_def);
  if (def_.arena.walls) add_wall_fixtures(*ground_, def_.arena, fixture_tag(FixtureKind::wall, 0));
  for (std::size_t i = 0; i < def_.arena.obstacles.size(); ++i)
    add_obstacle_fixture(i);
}

void World::add_obstacle_fixture(std::size_t index) {
  b2Fixture* fixture = sim::add_obstacle_fixture(*ground_, def_.arena.obstacles[index],
                                                 fixture_tag(FixtureKind::obstacle, index));
  if (obstacle_fixtures_.size() <= index) obstacle_fixtures_.resize(index + 1, nullptr);
  obstacle_fixtures_[index] = fixture;
}

std::size_t World::add_obstacle(Obstacle obstacle) {
  const bool usable = std::visit(
      [](const auto& o) {
        if constexpr (std::is_same_v<std::decay_t<decltype(o)>, BoxObstacle>) {
          return o.width_m > 0 && o.height_m > 0;
        } else {
          return o.radius_m > 0;
        }
      },
      obstacle);
  if (!usable) throw std::invalid_argument("an obstacle needs a positive size");
  def_.arena.obstacles.push_back(std::move(obstacle));
  const std::size_t index = def_.arena.obstacles.size() - 1;
  add_obstacle_fixture(index);
  return index;
}

bool World::remove_obstacle(std::size_t index) {
  if (!obstacle_present(index)) return false;
  // Box2D ends the contacts of the fixture here, so touching cars hear EndContact.
  ground_->DestroyFixture(obstacle_fixtures_[index]);
  obstacle_fixtures_[index] = nullptr;
  return true;
}

bool World::obstacle_present(std::size_t index) const {
  return index < obstacle_fixtures_.size() && obstacle_fixtures_[index] != nullptr;
}

Vehicle& World::add_vehicle(VehicleDef def) {
  const std::size_t index = vehicles_.size();
  vehicles_.push_back(std::unique_ptr<Vehicle>(new Vehicle(*this, index, std::move(def))));
  return *vehicles_.back();
}

void World::step() {
  for (auto& vehicle : vehicles_)
    vehicle->before_step(kStepSeconds);
  b2_->Step(static_cast<float>(kStepSeconds), def_.velocity_iterations, def_.position_iterations);
  ++steps_;
  for (auto& vehicle : vehicles_)
    vehicle->after_step(kStepSeconds);
}

void World::advance_to(Duration time) {
  if (time > requested_) requested_ = time;
  while (step_end(steps_ + 1) <= requested_)
    step();
}

std::vector<ContactEvent> World::take_contacts() {
  std::vector<ContactEvent> out;
  out.swap(contacts_);
  return out;
}

std::uint64_t World::state_hash() const {
  StateHasher hasher;
  hasher.add(steps_);
  hasher.add(static_cast<std::uint64_t>(vehicles_.size()));
  for (std::size_t i = 0; i < obstacle_fixtures_.size(); ++i)
    hasher.add(static_cast<std::uint64_t>(obstacle_present(i) ? i + 1 : 0));
  for (const auto& vehicle : vehicles_)
    vehicle->hash_state(hasher);
  return hasher.value();
}

namespace {

class ClosestHit final : public b2RayCastCallback {
 public:
  explicit ClosestHit(const b2Body* ignore) : ignore_(ignore) {}
  float ReportFixture(b2Fixture* fixture, const b2Vec2&, const b2Vec2&, float fraction) override {
    if (fixture->GetBody() == ignore_ || fixture->IsSensor()) return -1.0f;  // look through it
    fraction_ = fraction;
    return fraction;  // clip the ray: only closer hits from now on
  }
  std::optional<float> fraction() const { return fraction_; }

 private:
  const b2Body* ignore_;
  std::optional<float> fraction_;
};

}  // namespace

std::optional<double> World::ray_cast(Vec2 from, Vec2 to, const b2Body* ignore) const {
  const double length_m = length(to - from);
  if (!(length_m > 0)) return std::nullopt;
  ClosestHit callback(ignore);
  b2_->RayCast(&callback, b2Vec2(static_cast<float>(from.x_m), static_cast<float>(from.y_m)),
               b2Vec2(static_cast<float>(to.x_m), static_cast<float>(to.y_m)));
  if (!callback.fraction()) return std::nullopt;
  return static_cast<double>(*callback.fraction()) * length_m;
}

}  // namespace hil::sim
