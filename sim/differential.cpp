#include "sim/differential.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace hil::sim {

DifferentialChassis::DifferentialChassis(const DifferentialDef& def) : def_(def) {
  assert(def.speed_per_pwm_mps > 0 && def.effective_track_m > 0 && def.max_accel_mps2 > 0);
  assert(def.max_pwm > 0);
}

void DifferentialChassis::set_pwm(int left, int right) {
  left_pwm_ = std::clamp(left, -def_.max_pwm, def_.max_pwm);
  right_pwm_ = std::clamp(right, -def_.max_pwm, def_.max_pwm);
}

Twist DifferentialChassis::update(double dt_s) {
  const double max_change = def_.max_accel_mps2 * dt_s;
  left_mps_ = ramp(left_mps_, left_pwm_ * def_.speed_per_pwm_mps, max_change);
  right_mps_ = ramp(right_mps_, right_pwm_ * def_.speed_per_pwm_mps, max_change);
  left_travel_m_ += left_mps_ * dt_s;
  right_travel_m_ += right_mps_ * dt_s;
  return wheel_twist();
}

Twist DifferentialChassis::wheel_twist() const {
  return {(left_mps_ + right_mps_) / 2, 0.0, (right_mps_ - left_mps_) / def_.effective_track_m};
}

double DifferentialChassis::load() const {
  const double top = def_.max_pwm * def_.speed_per_pwm_mps;
  return std::min(1.0, (std::abs(left_mps_) + std::abs(right_mps_)) / (2 * top));
}

Footprint DifferentialChassis::footprint() const {
  return {def_.length_m, def_.width_m, 0.0, def_.mass_kg};
}

void DifferentialChassis::hash_state(StateHasher& hasher) const {
  hasher.add(left_pwm_);
  hasher.add(right_pwm_);
  hasher.add(left_mps_);
  hasher.add(right_mps_);
  hasher.add(left_travel_m_);
  hasher.add(right_travel_m_);
}

}  // namespace hil::sim
