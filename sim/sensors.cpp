#include "sim/sensors.hpp"

#include <algorithm>
#include <cmath>

namespace hil::sim {

SonarReading read_sonar(const SonarDef& def, const Pose& pose, const RayCaster& world,
                        Random& random, const SensorFaults& faults) {
  const Vec2 origin = pose.to_arena(def.mount_m);
  const double axis = pose.heading_rad + def.mount_angle_rad;
  // An ultrasonic echo comes back from the nearest surface anywhere in the cone.
  double nearest = INFINITY;
  const int rays = std::max(1, def.rays);
  for (int i = 0; i < rays; ++i) {
    const double offset = rays == 1 ? 0.0 : def.beam_half_angle_rad * (2.0 * i / (rays - 1) - 1.0);
    const double angle = axis + offset;
    const Vec2 end = origin + def.max_range_m * Vec2{std::cos(angle), std::sin(angle)};
    if (const auto hit = world.cast(origin, end)) nearest = std::min(nearest, *hit);
  }
  SonarReading reading;
  reading.echo = std::isfinite(nearest);
  double distance = reading.echo ? nearest : def.max_range_m;
  distance += random.normal(def.noise_stddev_m);
  reading.distance_m = std::clamp(distance, def.min_range_m, def.max_range_m);
  if (random.chance(faults.sonar_glitch_probability)) {
    reading.glitch = true;
    reading.distance_m = faults.sonar_glitch_m;
  }
  return reading;
}

LineReading line_reading_from(std::array<bool, 4> on) {
  static constexpr std::array<int, 4> kWeights = {-3, -1, 1, 3};
  LineReading reading;
  int sum = 0;
  int count = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    if (!on[i]) continue;
    reading.mask |= static_cast<std::uint8_t>(1u << (3 - i));
    sum += kWeights[i];
    ++count;
  }
  reading.deviation = count == 0 ? 0 : sum / count;
  return reading;
}

LineReading read_line_tracker(const LineTrackerDef& def, const Pose& pose, const Arena& arena) {
  // The four points share one rotation: sin and cos once, not four times
  // (the same arithmetic as Pose::to_arena, so the same points).
  const double c = std::cos(pose.heading_rad);
  const double s = std::sin(pose.heading_rad);
  std::array<bool, 4> on{};
  for (std::size_t i = 0; i < 4; ++i) {
    const Vec2 v{def.ahead_m, def.lateral_m[i]};
    on[i] = arena.on_tape(pose.position() + Vec2{c * v.x_m - s * v.y_m, s * v.x_m + c * v.y_m});
  }
  return line_reading_from(on);
}

namespace {

struct IrSide {
  int analog;
  bool obstacle;
  double distance_m;
};

IrSide read_ir_side(const IrDef& def, Vec2 mount, double angle_rad, const Pose& pose,
                    const RayCaster& world) {
  const Vec2 origin = pose.to_arena(mount);
  const double angle = pose.heading_rad + angle_rad;
  const Vec2 end = origin + def.range_m * Vec2{std::cos(angle), std::sin(angle)};
  const double distance = world.cast(origin, end).value_or(def.range_m);
  const int analog = static_cast<int>(std::lround(1023.0 * (1.0 - distance / def.range_m)));
  return {std::clamp(analog, 0, 1023), distance <= def.threshold_m, distance};
}

}  // namespace

IrReading read_ir(const IrDef& def, const Pose& pose, const RayCaster& world) {
  const IrSide left = read_ir_side(def, def.left_mount_m, def.left_angle_rad, pose, world);
  const IrSide right = read_ir_side(def, def.right_mount_m, def.right_angle_rad, pose, world);
  return {left.analog,    right.analog,    left.obstacle,
          right.obstacle, left.distance_m, right.distance_m};
}

}  // namespace hil::sim
