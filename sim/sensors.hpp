#pragma once
// The sensors a simulated car carries: ultrasonic range finder, 4-channel
// line tracker, RFID reader, left/right IR obstacle sensors. Mount points
// are in the body frame of the vehicle's reference point.

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "sim/arena.hpp"
#include "sim/geometry.hpp"
#include "sim/random.hpp"

namespace hil::sim {

/// Something that answers "how far along this segment is the first thing
/// in the way?" (the world, ignoring the asking vehicle's own body).
class RayCaster {
 public:
  virtual ~RayCaster() = default;
  /// Distance from `from` to the first hit before `to`, or nullopt.
  virtual std::optional<double> cast(Vec2 from, Vec2 to) const = 0;
};

struct SonarDef {
  Vec2 mount_m{0.14, 0.0};
  double mount_angle_rad = 0;           ///< beam axis, counter-clockwise from forward
  double min_range_m = 0.02;            ///< closer echoes read as this
  double max_range_m = 4.0;             ///< nothing within this reads as this
  double beam_half_angle_rad = 0.2618;  ///< 15 degrees either side of the axis
  int rays = 5;                         ///< rays spread across the beam (1 = the axis only)
  double noise_stddev_m = 0;            ///< Gaussian noise on each reading
  /// A new echo at most this often; reads in between return the last one.
  /// An HC-SR04 needs about 60 ms between pings for old echoes to die out.
  double period_s = 0.06;
};

struct SonarReading {
  double distance_m = 0;
  bool echo = false;    ///< false when nothing was within max range
  bool glitch = false;  ///< a sensor fault replaced the reading
  /// Whole centimetres, as the firmwares report it.
  int distance_cm() const { return static_cast<int>(distance_m * 100 + 0.5); }
};

/// Four downward reflectance sensors in a row across the car, H4 on the
/// left to H1 on the right (as the car sees it).
struct LineTrackerDef {
  double ahead_m = 0.12;  ///< row distance ahead of the reference point
  /// Lateral offsets of H4, H3, H2, H1 (positive to the left).
  std::array<double, 4> lateral_m{0.036, 0.012, -0.012, -0.036};
};

struct LineReading {
  /// Bit 3 = H4 ... bit 0 = H1; a set bit sees tape. Printed b4b3b2b1 it
  /// reads left to right as the car sees the floor.
  std::uint8_t mask = 0;
  /// Where the tape lies across the row: the mean of the weights -3, -1,
  /// +1, +3 (H4..H1) of the sensors on tape, rounded toward zero; positive
  /// when the tape is to the right, so the car must turn right. 0 when no
  /// sensor sees tape (see `lost`).
  int deviation = 0;
  bool lost() const { return mask == 0; }
};

struct RfidReaderDef {
  Vec2 mount_m{0.0, 0.0};  ///< reads a tag whose radius contains this point
};

/// Left and right IR obstacle sensors: an analog value that rises as an
/// obstacle nears and a digital output that trips under a threshold.
struct IrDef {
  Vec2 left_mount_m{0.09, 0.06};
  double left_angle_rad = 0.5236;  ///< 30 degrees to the left of forward
  Vec2 right_mount_m{0.09, -0.06};
  double right_angle_rad = -0.5236;
  double range_m = 0.30;      ///< analog reads 0 beyond this
  double threshold_m = 0.15;  ///< digital trips at or under this
};

struct IrReading {
  int left_analog = 0;  ///< 0..1023 (10-bit ADC): 1023 touching, 0 at range or beyond
  int right_analog = 0;
  bool left_obstacle = false;  ///< digital output: obstacle within the threshold
  bool right_obstacle = false;
  double left_distance_m = 0;  ///< true distance (range when nothing)
  double right_distance_m = 0;
};

/// Faults the sensors and wheels can be given (all off by default).
struct SensorFaults {
  double sonar_glitch_probability = 0;  ///< chance a reading is replaced by the glitch value
  double sonar_glitch_m = 0;            ///< the value a glitched reading shows
  double rfid_miss_probability = 0;     ///< chance a pass over a tag is not read at all
  double wheel_slip_fraction = 0;       ///< 0..1: the ground moves this much less than the wheels
  double battery_sag_v = 0;             ///< volts taken off the terminal voltage
};

SonarReading read_sonar(const SonarDef& def, const Pose& pose, const RayCaster& world,
                        Random& random, const SensorFaults& faults);
LineReading read_line_tracker(const LineTrackerDef& def, const Pose& pose, const Arena& arena);
IrReading read_ir(const IrDef& def, const Pose& pose, const RayCaster& world);

/// Mask and deviation for the four sensor states H4..H1.
LineReading line_reading_from(std::array<bool, 4> on_tape_h4_to_h1);

}  // namespace hil::sim
