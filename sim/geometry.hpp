#pragma once
// Plane geometry shared by the arena, the chassis models and the sensors.
// Arena frame: origin at the arena's lower-left corner, x to the right, y up,
// metres; angles in radians, counter-clockwise from +x. Body frame: x forward,
// y to the left of the vehicle.

#include <cmath>
#include <numbers>

namespace hil::sim {

struct Vec2 {
  double x_m = 0;
  double y_m = 0;

  friend Vec2 operator+(Vec2 a, Vec2 b) { return {a.x_m + b.x_m, a.y_m + b.y_m}; }
  friend Vec2 operator-(Vec2 a, Vec2 b) { return {a.x_m - b.x_m, a.y_m - b.y_m}; }
  friend Vec2 operator*(double k, Vec2 a) { return {k * a.x_m, k * a.y_m}; }
  friend bool operator==(const Vec2&, const Vec2&) = default;
};

inline double dot(Vec2 a, Vec2 b) {
  return a.x_m * b.x_m + a.y_m * b.y_m;
}
inline double length(Vec2 a) {
  return std::hypot(a.x_m, a.y_m);
}

/// `v` turned counter-clockwise by `angle_rad`.
inline Vec2 rotate(Vec2 v, double angle_rad) {
  const double c = std::cos(angle_rad);
  const double s = std::sin(angle_rad);
  return {c * v.x_m - s * v.y_m, s * v.x_m + c * v.y_m};
}

/// Where a vehicle is: its reference point in the arena and its heading.
struct Pose {
  double x_m = 0;
  double y_m = 0;
  double heading_rad = 0;

  Vec2 position() const { return {x_m, y_m}; }
  /// A point given in this pose's body frame, in arena coordinates.
  Vec2 to_arena(Vec2 body_point) const { return position() + rotate(body_point, heading_rad); }
  friend bool operator==(const Pose&, const Pose&) = default;
};

/// Body-frame velocity of a vehicle's reference point.
struct Twist {
  double vx_mps = 0;    ///< forward
  double vy_mps = 0;    ///< to the left
  double wz_radps = 0;  ///< counter-clockwise
  friend bool operator==(const Twist&, const Twist&) = default;
};

/// Squared distance from `p` to the segment a-b.
inline double distance_squared_to_segment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double len2 = dot(ab, ab);
  double t = len2 > 0 ? dot(p - a, ab) / len2 : 0.0;
  t = t < 0 ? 0 : (t > 1 ? 1 : t);
  const Vec2 d = p - (a + t * ab);
  return dot(d, d);
}

/// Distance from `p` to the segment a-b.
inline double distance_to_segment(Vec2 p, Vec2 a, Vec2 b) {
  return std::sqrt(distance_squared_to_segment(p, a, b));
}

/// `angle_rad` wrapped into (-pi, pi].
inline double wrap_angle(double angle_rad) {
  constexpr double two_pi = 2 * std::numbers::pi;
  double a = std::fmod(angle_rad + std::numbers::pi, two_pi);
  if (a <= 0) a += two_pi;
  return a - std::numbers::pi;
}

inline constexpr double deg_to_rad(double deg) {
  return deg * std::numbers::pi / 180.0;
}
inline constexpr double rad_to_deg(double rad) {
  return rad * 180.0 / std::numbers::pi;
}

/// `value` rounded to a multiple of `step` (step > 0): how poses and times
/// are written where people and pages read them.
inline double round_to(double value, double step) {
  return std::round(value / step) * step;
}

}  // namespace hil::sim
