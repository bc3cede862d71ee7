#include "sim/ackermann.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace hil::sim {

AckermannChassis::AckermannChassis(const AckermannDef& def) : def_(def) {
  assert(def.wheelbase_m > 0 && def.max_steering_rad > 0 && def.max_steering_rad < 1.5);
  assert(def.steering_rate_radps > 0 && def.max_speed_mps > 0);
  assert(def.max_accel_mps2 > 0 && def.max_decel_mps2 > 0);
}

void AckermannChassis::set_speed_target(double speed_mps) {
  goal_m_.reset();
  speed_target_mps_ = std::clamp(speed_mps, -def_.max_speed_mps, def_.max_speed_mps);
}

void AckermannChassis::set_steering_target(double angle_rad) {
  steering_target_rad_ = std::clamp(angle_rad, -def_.max_steering_rad, def_.max_steering_rad);
}

void AckermannChassis::drive_distance(double distance_m, double speed_mps) {
  goal_m_ = distance_m;
  goal_speed_mps_ = std::clamp(std::abs(speed_mps), 0.0, def_.max_speed_mps);
}

Twist AckermannChassis::update(double dt_s) {
  if (goal_m_) {
    // Fastest speed that can still brake to zero within the remaining distance
    // (planned at 80 % of the brake limit so the stepwise ramp keeps up).
    const double remaining = std::abs(*goal_m_);
    double v = std::min(goal_speed_mps_, std::sqrt(1.6 * def_.max_decel_mps2 * remaining));
    v = std::min(v, remaining / dt_s);
    speed_target_mps_ = *goal_m_ >= 0 ? v : -v;
  }
  const bool speeding_up = std::abs(speed_target_mps_) > std::abs(speed_mps_) &&
                           (speed_target_mps_ >= 0) == (speed_mps_ >= 0);
  const double limit = (speeding_up ? def_.max_accel_mps2 : def_.max_decel_mps2) * dt_s;
  speed_mps_ = ramp(speed_mps_, speed_target_mps_, limit);
  steering_rad_ = ramp(steering_rad_, steering_target_rad_, def_.steering_rate_radps * dt_s);

  const double step_m = speed_mps_ * dt_s;
  odometer_m_ += std::abs(step_m);
  if (goal_m_) {
    const double before = *goal_m_;
    *goal_m_ -= step_m;
    // Done once the wheels have covered the distance to a tenth of a
    // millimetre, or have just rolled past it.
    if (std::abs(*goal_m_) < 1e-4 || (before > 0) != (*goal_m_ > 0)) {
      goal_m_.reset();
      speed_target_mps_ = 0;
    }
  }
  return wheel_twist();
}

Twist AckermannChassis::wheel_twist() const {
  return {speed_mps_, 0.0, speed_mps_ * std::tan(steering_rad_) / def_.wheelbase_m};
}

double AckermannChassis::load() const {
  return std::min(1.0, std::abs(speed_mps_) / def_.max_speed_mps);
}

void AckermannChassis::stop() {
  goal_m_.reset();
  speed_target_mps_ = 0;
}

Footprint AckermannChassis::footprint() const {
  return {def_.length_m, def_.width_m, def_.length_m / 2 - def_.rear_overhang_m, def_.mass_kg};
}

void AckermannChassis::hash_state(StateHasher& hasher) const {
  hasher.add(speed_target_mps_);
  hasher.add(speed_mps_);
  hasher.add(steering_target_rad_);
  hasher.add(steering_rad_);
  hasher.add(odometer_m_);
  hasher.add(goal_m_.value_or(std::numeric_limits<double>::quiet_NaN()));
}

}  // namespace hil::sim
