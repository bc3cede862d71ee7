#pragma once
// Differential (skid-steer) chassis driven by a PWM duty per side: the
// Arduino robot and the Leka robot.

#include "sim/chassis.hpp"

namespace hil::sim {

struct DifferentialDef {
  /// Ground speed of a side per PWM unit (0..255). The default is the
  /// Arduino firmware's calibration: 18 ms per cm at its base PWM of 140.
  double speed_per_pwm_mps = (1.0 / 1.8) / 140.0;
  /// Track width that the turn rate implies: (right - left) / this. Wider
  /// than the wheels' spacing on a skid-steer robot, whose tyres scrub in
  /// a turn. The default makes 6 ms per degree true at PWM 140.
  double effective_track_m = 0.381972;
  double max_accel_mps2 = 2.0;  ///< per side; the same limit brakes
  int max_pwm = 255;
  double length_m = 0.20;
  double width_m = 0.16;
  double mass_kg = 1.0;
};

class DifferentialChassis final : public Chassis {
 public:
  explicit DifferentialChassis(const DifferentialDef& def);

  /// Signed duty per side, -max_pwm..max_pwm (clamped); positive drives forward.
  void set_pwm(int left, int right);
  int left_pwm() const { return left_pwm_; }
  int right_pwm() const { return right_pwm_; }

  double left_speed_mps() const { return left_mps_; }
  double right_speed_mps() const { return right_mps_; }
  /// Distance each side's wheels have rolled, signed, metres.
  double left_travel_m() const { return left_travel_m_; }
  double right_travel_m() const { return right_travel_m_; }

  const DifferentialDef& def() const { return def_; }

  Twist update(double dt_s) override;
  Twist wheel_twist() const override;
  double load() const override;
  void stop() override { set_pwm(0, 0); }
  Footprint footprint() const override;
  void hash_state(StateHasher& hasher) const override;

 private:
  DifferentialDef def_;
  int left_pwm_ = 0;
  int right_pwm_ = 0;
  double left_mps_ = 0;
  double right_mps_ = 0;
  double left_travel_m_ = 0;
  double right_travel_m_ = 0;
};

}  // namespace hil::sim
