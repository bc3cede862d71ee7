#include "sim/sensors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hil::sim {

SonarReading read_sonar(const SonarDef& def, const Pose& pose, const RayCaster& world,
                        Random& random, const SensorFaults& faults) {
  const Vec2 origin = pose.to_arena(def.mount_m);
  const double axis = pose.heading_rad + def.mount_angle_rad;
  // An ultrasonic echo comes back from the nearest surface anywhere in the cone.
  double nearest = std::numeric_limits<double>::infinity();
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

namespace {

// Arena::on_tape for the line tracker's four points at once, with the same
// answer for each: a segment whose box (grown by half the tape's width)
// misses the box round all four points misses each of them, so it is
// skipped with one test instead of four; the per-point test is Tape::covers'.
std::array<bool, 4> on_tape(const Arena& arena, const std::array<Vec2, 4>& points) {
  std::array<bool, 4> on{};
  Vec2 lo = points[0];
  Vec2 hi = points[0];
  for (const Vec2& p : points) {
    lo = {std::min(lo.x_m, p.x_m), std::min(lo.y_m, p.y_m)};
    hi = {std::max(hi.x_m, p.x_m), std::max(hi.y_m, p.y_m)};
  }
  for (const Tape& tape : arena.tapes) {
    const double half = tape.width_m / 2;
    const double half2 = half * half;
    const auto visit = [&](Vec2 a, Vec2 b) {
      const double min_x = std::min(a.x_m, b.x_m) - half;
      const double max_x = std::max(a.x_m, b.x_m) + half;
      const double min_y = std::min(a.y_m, b.y_m) - half;
      const double max_y = std::max(a.y_m, b.y_m) + half;
      if (hi.x_m < min_x || lo.x_m > max_x || hi.y_m < min_y || lo.y_m > max_y) return;
      for (std::size_t i = 0; i < points.size(); ++i) {
        const Vec2 p = points[i];
        if (on[i] || p.x_m < min_x || p.x_m > max_x || p.y_m < min_y || p.y_m > max_y) continue;
        on[i] = distance_squared_to_segment(p, a, b) <= half2;
      }
    };
    const auto& pts = tape.points_m;
    if (pts.size() == 1) visit(pts[0], pts[0]);
    for (std::size_t i = 0; i + 1 < pts.size(); ++i)
      visit(pts[i], pts[i + 1]);
    if (tape.closed && pts.size() > 2) visit(pts.back(), pts.front());
  }
  return on;
}

}  // namespace

LineReading read_line_tracker(const LineTrackerDef& def, const Pose& pose, const Arena& arena) {
  // The four points share one rotation: sin and cos once, not four times
  // (the same arithmetic as Pose::to_arena, so the same points).
  const double c = std::cos(pose.heading_rad);
  const double s = std::sin(pose.heading_rad);
  std::array<Vec2, 4> points{};
  for (std::size_t i = 0; i < 4; ++i) {
    const Vec2 v{def.ahead_m, def.lateral_m[i]};
    points[i] = pose.position() + Vec2{c * v.x_m - s * v.y_m, s * v.x_m + c * v.y_m};
  }
  return line_reading_from(on_tape(arena, points));
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
