#include "sim/mecanum.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace hil::sim {

MecanumChassis::MecanumChassis(const MecanumDef& def) : def_(def) {
  assert(def.wheel_radius_m > 0 && def.half_wheelbase_m > 0 && def.half_track_m > 0);
  assert(def.top_speed_mps > 0 && def.max_accel_mps2 > 0 && def.max_angular_accel_radps2 > 0);
}

MecanumWheels MecanumChassis::inverse_kinematics(const MecanumDef& def, const Twist& t) {
  const double k = def.half_wheelbase_m + def.half_track_m;
  const double r = def.wheel_radius_m;
  return {(t.vx_mps - t.vy_mps - k * t.wz_radps) / r, (t.vx_mps + t.vy_mps + k * t.wz_radps) / r,
          (t.vx_mps + t.vy_mps - k * t.wz_radps) / r, (t.vx_mps - t.vy_mps + k * t.wz_radps) / r};
}

Twist MecanumChassis::forward_kinematics(const MecanumDef& def, const MecanumWheels& w) {
  const double k = def.half_wheelbase_m + def.half_track_m;
  const double r = def.wheel_radius_m;
  return {
      r / 4 * (w.front_left_radps + w.front_right_radps + w.rear_left_radps + w.rear_right_radps),
      r / 4 * (-w.front_left_radps + w.front_right_radps + w.rear_left_radps - w.rear_right_radps),
      r / (4 * k) *
          (-w.front_left_radps + w.front_right_radps - w.rear_left_radps + w.rear_right_radps)};
}

void MecanumChassis::set_target(const Twist& target) {
  const MecanumWheels w = inverse_kinematics(def_, target);
  const double fastest = std::max({std::abs(w.front_left_radps), std::abs(w.front_right_radps),
                                   std::abs(w.rear_left_radps), std::abs(w.rear_right_radps)});
  const double limit = max_wheel_radps();
  const double scale = fastest > limit ? limit / fastest : 1.0;
  target_ = {target.vx_mps * scale, target.vy_mps * scale, target.wz_radps * scale};
}

void MecanumChassis::set_wheel_targets(const MecanumWheels& wheels) {
  set_target(forward_kinematics(def_, wheels));
}

double MecanumChassis::speed_for_percent_mps(double percent) const {
  return def_.top_speed_mps * std::clamp(percent, 0.0, 100.0) / 100.0;
}

std::array<double, 4> MecanumChassis::motor_rpm() const {
  const MecanumWheels w = wheels();
  constexpr double to_rpm = 60.0 / (2 * std::numbers::pi);
  return {w.rear_left_radps * to_rpm, w.front_left_radps * to_rpm, w.front_right_radps * to_rpm,
          w.rear_right_radps * to_rpm};
}

Twist MecanumChassis::update(double dt_s) {
  // Ramp the translation as one vector so a diagonal start keeps its direction.
  const double dvx = target_.vx_mps - current_.vx_mps;
  const double dvy = target_.vy_mps - current_.vy_mps;
  const double dv = std::hypot(dvx, dvy);
  const double max_dv = def_.max_accel_mps2 * dt_s;
  if (dv <= max_dv) {
    current_.vx_mps = target_.vx_mps;
    current_.vy_mps = target_.vy_mps;
  } else {
    current_.vx_mps += dvx * max_dv / dv;
    current_.vy_mps += dvy * max_dv / dv;
  }
  current_.wz_radps =
      ramp(current_.wz_radps, target_.wz_radps, def_.max_angular_accel_radps2 * dt_s);
  return current_;
}

double MecanumChassis::load() const {
  const MecanumWheels w = wheels();
  const double sum = std::abs(w.front_left_radps) + std::abs(w.front_right_radps) +
                     std::abs(w.rear_left_radps) + std::abs(w.rear_right_radps);
  return std::min(1.0, sum / (4 * max_wheel_radps()));
}

Footprint MecanumChassis::footprint() const {
  return {def_.length_m, def_.width_m, 0.0, def_.mass_kg};
}

void MecanumChassis::hash_state(StateHasher& hasher) const {
  hasher.add(target_);
  hasher.add(current_);
}

}  // namespace hil::sim
