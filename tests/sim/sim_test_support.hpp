#pragma once
// Small helpers shared by the simulation tests.

#include "sim/world.hpp"

namespace hil::sim::test {

/// An arena with no walls, obstacles or tape: room to drive in any direction.
inline Arena open_field(double size_m = 40.0) {
  Arena arena;
  arena.name = "open";
  arena.width_m = size_m;
  arena.height_m = size_m;
  arena.walls = true;
  arena.start = Pose{size_m / 2, size_m / 2, 0.0};
  return arena;
}

/// `def` starting at `start`.
inline VehicleDef starting_at(VehicleDef def, Pose start) {
  def.start = start;
  return def;
}

inline Duration seconds(double s) {
  return Duration{static_cast<std::int64_t>(s * 1e9)};
}

}  // namespace hil::sim::test
