#pragma once
// Four-wheel mecanum chassis (the LOGI car): moves in any direction and
// turns in place. Rollers in the usual X layout seen from above.

#include <array>

#include "sim/chassis.hpp"

namespace hil::sim {

struct MecanumDef {
  double wheel_radius_m = 0.04;
  double half_wheelbase_m = 0.085;  ///< body centre to front (or rear) axle
  double half_track_m = 0.095;      ///< body centre to a wheel's contact line
  double top_speed_mps = 0.5;       ///< straight-ahead speed at speed 100 %
  double max_accel_mps2 = 1.0;      ///< translational acceleration limit
  double max_angular_accel_radps2 = 8.0;
  double length_m = 0.28;
  double width_m = 0.24;
  double mass_kg = 2.0;
};

/// Wheel angular speeds in rad/s; positive turns a wheel so that it drives
/// its side of the car forward.
struct MecanumWheels {
  double front_left_radps = 0;
  double front_right_radps = 0;
  double rear_left_radps = 0;
  double rear_right_radps = 0;
};

class MecanumChassis final : public Chassis {
 public:
  explicit MecanumChassis(const MecanumDef& def);

  /// Wheel speeds that give body twist `twist` (inverse kinematics).
  static MecanumWheels inverse_kinematics(const MecanumDef& def, const Twist& twist);
  /// Body twist that wheel speeds `wheels` give (forward kinematics).
  static Twist forward_kinematics(const MecanumDef& def, const MecanumWheels& wheels);

  /// Drive toward body twist `target`; scaled down as a whole if a wheel
  /// would pass the top speed.
  void set_target(const Twist& target);
  /// Drive toward wheel speeds `wheels` (same limits).
  void set_wheel_targets(const MecanumWheels& wheels);
  Twist target() const { return target_; }

  /// Body speed for a speed setting of `percent` (0..100, clamped).
  double speed_for_percent_mps(double percent) const;
  /// Top wheel speed in rad/s (the wheel speed at speed 100 % straight ahead).
  double max_wheel_radps() const { return def_.top_speed_mps / def_.wheel_radius_m; }

  MecanumWheels wheels() const { return inverse_kinematics(def_, current_); }
  /// Motor RPM in the LOGI firmware's order M1:M2:M3:M4 = LR:LF:RF:RR.
  std::array<double, 4> motor_rpm() const;

  const MecanumDef& def() const { return def_; }

  Twist update(double dt_s) override;
  Twist wheel_twist() const override { return current_; }
  double load() const override;
  void stop() override { target_ = {}; }
  Footprint footprint() const override;
  void hash_state(StateHasher& hasher) const override;

 private:
  MecanumDef def_;
  Twist target_;
  Twist current_;
};

}  // namespace hil::sim
