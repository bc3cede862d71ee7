#pragma once
// Simulation time. The world advances in fixed steps of 1/120 s whatever the
// caller's clock does; step k ends at exactly k * 1e9 / 120 ns (rounded
// down), so stepping in one call or in many small advances lands on the same
// steps.

#include <chrono>
#include <cstdint>

namespace hil::sim {

/// Time since the world was made (the same unit as hil::link::Time).
using Duration = std::chrono::nanoseconds;

inline constexpr std::int64_t kStepsPerSecond = 120;
inline constexpr double kStepSeconds = 1.0 / kStepsPerSecond;

/// When fixed step number `step` (counting from 1) ends.
constexpr Duration step_end(std::int64_t step) {
  return Duration{step * 1'000'000'000 / kStepsPerSecond};
}

inline double to_seconds(Duration d) {
  return std::chrono::duration<double>(d).count();
}

}  // namespace hil::sim
