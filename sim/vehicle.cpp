#include "sim/vehicle.hpp"

#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>

#include "sim/fixture_tag.hpp"
#include "sim/world.hpp"

namespace hil::sim {

namespace {

std::unique_ptr<Chassis> make_chassis(const ChassisDef& def) {
  return std::visit(
      [](const auto& d) -> std::unique_ptr<Chassis> {
        using T = std::decay_t<decltype(d)>;
        if constexpr (std::is_same_v<T, MecanumDef>) return std::make_unique<MecanumChassis>(d);
        if constexpr (std::is_same_v<T, AckermannDef>) return std::make_unique<AckermannChassis>(d);
        if constexpr (std::is_same_v<T, DifferentialDef>)
          return std::make_unique<DifferentialChassis>(d);
      },
      def);
}

b2Vec2 to_b2(Vec2 v) {
  return b2Vec2(static_cast<float>(v.x_m), static_cast<float>(v.y_m));
}

// Box2D keeps floats; hil's geometry is in doubles.
Vec2 from_b2(b2Vec2 v) {
  return {static_cast<double>(v.x), static_cast<double>(v.y)};
}

double angle_of(const b2Body& body) {
  return static_cast<double>(body.GetAngle());
}

}  // namespace

Vehicle::Vehicle(World& world, std::size_t index, VehicleDef def)
    : world_(world),
      index_(index),
      name_(def.name),
      def_(std::move(def)),
      chassis_(make_chassis(def_.chassis)),
      battery_(def_.battery),
      random_(mix_seed(world.seed(), index)) {
  const Pose start = def_.start.value_or(world.arena().start);
  const Footprint footprint = chassis_->footprint();
  b2BodyDef body_def;
  body_def.type = b2_dynamicBody;
  body_def.position = to_b2(start.position());
  body_def.angle = static_cast<float>(start.heading_rad);
  body_def.allowSleep = false;
  body_ = world.b2_->CreateBody(&body_def);
  b2PolygonShape shape;
  shape.SetAsBox(static_cast<float>(footprint.length_m / 2),
                 static_cast<float>(footprint.width_m / 2),
                 b2Vec2(static_cast<float>(footprint.center_ahead_m), 0.0f), 0.0f);
  b2FixtureDef fixture;
  fixture.shape = &shape;
  fixture.density =
      static_cast<float>(footprint.mass_kg / (footprint.length_m * footprint.width_m));
  fixture.friction = 0.3f;
  fixture.restitution = 0.0f;
  fixture.userData.pointer = detail::fixture_tag(detail::FixtureKind::vehicle, index);
  body_->CreateFixture(&fixture);
  odometry_.pose = start;
}

Vehicle::~Vehicle() {
  if (body_ != nullptr) world_.b2_->DestroyBody(body_);
}

Pose Vehicle::pose() const {
  const b2Vec2 p = body_->GetPosition();
  return {static_cast<double>(p.x), static_cast<double>(p.y), wrap_angle(angle_of(*body_))};
}

Twist Vehicle::velocity() const {
  const b2Vec2 v = body_->GetLinearVelocityFromLocalPoint(b2Vec2(0.0f, 0.0f));
  const Vec2 body = rotate(from_b2(v), -angle_of(*body_));
  return {body.x_m, body.y_m, static_cast<double>(body_->GetAngularVelocity())};
}

void Vehicle::place(const Pose& pose) {
  body_->SetTransform(to_b2(pose.position()), static_cast<float>(pose.heading_rad));
  body_->SetLinearVelocity(b2Vec2(0.0f, 0.0f));
  body_->SetAngularVelocity(0.0f);
}

void Vehicle::before_step(double dt_s) {
  // Box2D keeps the angle unwrapped in a float; a car circling for hours
  // would lose turning precision, so bring it back near zero now and then.
  if (const float angle = body_->GetAngle(); std::abs(angle) > 8.0f) {
    body_->SetTransform(body_->GetPosition(),
                        static_cast<float>(wrap_angle(static_cast<double>(angle))));
  }
  const Twist wheels = chassis_->update(dt_s);

  // Odometry believes the wheels: integrate their twist at the mid-step heading.
  Pose& est = odometry_.pose;
  const double mid_heading = est.heading_rad + wheels.wz_radps * dt_s / 2;
  const Vec2 moved = rotate({wheels.vx_mps * dt_s, wheels.vy_mps * dt_s}, mid_heading);
  est.x_m += moved.x_m;
  est.y_m += moved.y_m;
  est.heading_rad = wrap_angle(est.heading_rad + wheels.wz_radps * dt_s);
  odometry_.distance_m += std::hypot(wheels.vx_mps, wheels.vy_mps) * dt_s;

  // The ground gets what the wheels give, less slip; Box2D then resolves
  // contacts, so a wall stops or deflects the body whatever the wheels do.
  const double grip = 1.0 - std::clamp(def_.faults.wheel_slip_fraction, 0.0, 1.0);
  const double angle = angle_of(*body_);
  const Vec2 v_ref = rotate({wheels.vx_mps * grip, wheels.vy_mps * grip}, angle);
  const double wz = wheels.wz_radps * grip;
  // Box2D's linear velocity is the centre of mass's: add w x (com - reference).
  const b2Vec2 com = body_->GetWorldCenter() - body_->GetPosition();
  body_->SetLinearVelocity(b2Vec2(static_cast<float>(v_ref.x_m - wz * static_cast<double>(com.y)),
                                  static_cast<float>(v_ref.y_m + wz * static_cast<double>(com.x))));
  body_->SetAngularVelocity(static_cast<float>(wz));
}

void Vehicle::after_step(double dt_s) {
  battery_.update(chassis_->load(), dt_s, def_.faults.battery_sag_v);
  const RfidTag* tag = world_.arena().tag_at(pose().to_arena(def_.rfid.mount_m));
  if (tag != tag_under_) {
    tag_under_ = tag;
    // A missed read misses the whole pass, as a reader that failed to wake the tag does.
    tag_missed_ = tag != nullptr && random_.chance(def_.faults.rfid_miss_probability);
    if (tag != nullptr && !tag_missed_) ++rfid_reads_;
  }
}

SonarReading Vehicle::sonar() {
  const Duration now = world_.time();
  const Duration period{static_cast<std::int64_t>(def_.sonar.period_s * 1e9)};
  if (!sonar_last_ || now - sonar_time_ >= period) {
    sonar_last_ = read_sonar(def_.sonar, pose(), *this, random_, def_.faults);
    sonar_time_ = now;
  }
  return *sonar_last_;
}

LineReading Vehicle::line_tracker() const {
  return read_line_tracker(def_.line_tracker, pose(), world_.arena());
}

std::optional<std::string> Vehicle::rfid() const {
  if (tag_under_ == nullptr || tag_missed_) return std::nullopt;
  return tag_under_->id;
}

IrReading Vehicle::ir() const {
  return read_ir(def_.ir, pose(), *this);
}

std::optional<double> Vehicle::cast(Vec2 from, Vec2 to) const {
  return world_.ray_cast(from, to, body_);
}

void Vehicle::hash_state(StateHasher& hasher) const {
  const b2Transform& xf = body_->GetTransform();
  hasher.add(xf.p.x);
  hasher.add(xf.p.y);
  hasher.add(xf.q.s);
  hasher.add(xf.q.c);
  const b2Vec2 v = body_->GetLinearVelocity();
  hasher.add(v.x);
  hasher.add(v.y);
  hasher.add(body_->GetAngularVelocity());
  chassis_->hash_state(hasher);
  battery_.hash_state(hasher);
  hasher.add(odometry_);
  hasher.add(rfid_reads_);
  hasher.add(tag_missed_);
  hasher.add(contacts_);
  hasher.add(sonar_time_);
  Random copy = random_;  // the generator's next output stands for its state
  hasher.add(copy.next());
}

}  // namespace hil::sim
