#pragma once
// Car-like chassis with steered front wheels (the WR8 vehicle), as the
// kinematic bicycle model: the reference point is the middle of the rear
// axle, and the car turns about a point on the rear axle's line at radius
// wheelbase / tan(steering angle).

#include <optional>

#include "sim/chassis.hpp"

namespace hil::sim {

struct AckermannDef {
  double wheelbase_m = 0.26;
  double max_steering_rad = 0.5236;     ///< 30 degrees either way
  double steering_rate_radps = 3.1416;  ///< servo slew: 180 degrees per second
  double max_speed_mps = 2.0;
  double max_accel_mps2 = 1.0;
  double max_decel_mps2 = 2.0;
  double length_m = 0.42;
  double width_m = 0.20;
  double rear_overhang_m = 0.08;  ///< footprint behind the rear axle
  double mass_kg = 2.5;
};

class AckermannChassis final : public Chassis {
 public:
  explicit AckermannChassis(const AckermannDef& def);

  /// Drive at `speed_mps` (signed, clamped to the top speed) until told otherwise;
  /// cancels a distance goal.
  void set_speed_target(double speed_mps);
  /// Steer toward `angle_rad` (positive turns left), clamped to the limit;
  /// the wheels get there at the slew rate.
  void set_steering_target(double angle_rad);
  /// Drive `distance_m` (negative backwards) at up to `speed_mps`, braking
  /// in time to stop on the distance, measured by the wheels.
  void drive_distance(double distance_m, double speed_mps);
  /// True while a distance goal is being driven.
  bool driving_distance() const { return goal_m_.has_value(); }

  double speed_mps() const { return speed_mps_; }
  double steering_rad() const { return steering_rad_; }
  double steering_target_rad() const { return steering_target_rad_; }
  /// Distance the wheels have rolled, forwards and backwards added up.
  double odometer_m() const { return odometer_m_; }

  const AckermannDef& def() const { return def_; }

  Twist update(double dt_s) override;
  Twist wheel_twist() const override;
  double load() const override;
  void stop() override;
  Footprint footprint() const override;
  void hash_state(StateHasher& hasher) const override;

 private:
  AckermannDef def_;
  double speed_target_mps_ = 0;
  double speed_mps_ = 0;
  double steering_target_rad_ = 0;
  double steering_rad_ = 0;
  double odometer_m_ = 0;
  std::optional<double> goal_m_;  ///< signed distance still to go
  double goal_speed_mps_ = 0;
};

}  // namespace hil::sim
