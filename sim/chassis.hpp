#pragma once
// The drive-train interface every chassis model implements. A model turns
// its own commands (wheel speeds, steering, PWM) into the body-frame twist
// its wheels try to give the vehicle; the world applies that twist to the
// Box2D body, and Box2D decides what walls and obstacles let through.

#include "sim/geometry.hpp"
#include "sim/random.hpp"

namespace hil::sim {

/// The rectangle a chassis occupies, relative to its reference point.
struct Footprint {
  double length_m = 0.3;
  double width_m = 0.25;
  double center_ahead_m = 0;  ///< footprint centre this far ahead of the reference point
  double mass_kg = 1.0;
};

class Chassis {
 public:
  virtual ~Chassis() = default;

  /// Advances the motors by one step of `dt_s` (ramps, slew, distance
  /// goals) and returns the twist the wheels now drive at the reference point.
  virtual Twist update(double dt_s) = 0;
  /// The twist the wheels drive now (the last update's result).
  virtual Twist wheel_twist() const = 0;
  /// Motor load, 0 (idle) .. 1 (every motor at full speed), for the battery.
  virtual double load() const = 0;
  /// Commands every motor to zero; the chassis ramps down at its limits.
  virtual void stop() = 0;
  virtual Footprint footprint() const = 0;
  /// Adds the model's state to a determinism hash.
  virtual void hash_state(StateHasher& hasher) const = 0;
};

/// Moves `current` toward `target` by at most `max_change`.
inline double ramp(double current, double target, double max_change) {
  if (target > current + max_change) return current + max_change;
  if (target < current - max_change) return current - max_change;
  return target;
}

}  // namespace hil::sim
