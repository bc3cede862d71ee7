#pragma once
// One simulated car: a chassis model driving a Box2D body, its sensors,
// odometry and battery, and the sensor faults it has been given.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>

#include "sim/ackermann.hpp"
#include "sim/battery.hpp"
#include "sim/differential.hpp"
#include "sim/mecanum.hpp"
#include "sim/sensors.hpp"
#include "sim/time.hpp"

class b2Body;

namespace hil::sim {

class World;

using ChassisDef = std::variant<MecanumDef, AckermannDef, DifferentialDef>;

struct VehicleDef {
  std::string name = "car";
  ChassisDef chassis = MecanumDef{};
  std::optional<Pose> start;  ///< the arena's start pose when empty
  SonarDef sonar;
  LineTrackerDef line_tracker;
  RfidReaderDef rfid;
  IrDef ir;
  BatteryDef battery;
  SensorFaults faults;
};

/// Wheel odometry: what the car believes from its wheels alone. It counts
/// wheel slip as distance, and knows nothing of walls that stopped it.
struct Odometry {
  double distance_m = 0;  ///< path length the wheels rolled
  Pose pose;              ///< dead-reckoned from the start pose
};

class Vehicle : private RayCaster {
 public:
  ~Vehicle() override;
  Vehicle(const Vehicle&) = delete;
  Vehicle& operator=(const Vehicle&) = delete;

  const std::string& name() const { return name_; }
  std::size_t index() const { return index_; }

  /// Where the reference point is, from the physics (ground truth).
  Pose pose() const;
  /// Body-frame twist of the reference point, from the physics: what the
  /// car really does after walls and obstacles had their say.
  Twist velocity() const;
  /// Moves the car to `pose` at rest (an operator picking it up).
  void place(const Pose& pose);

  Chassis& chassis() { return *chassis_; }
  /// The chassis as its model, or nullptr when it is another model.
  MecanumChassis* mecanum() { return dynamic_cast<MecanumChassis*>(chassis_.get()); }
  AckermannChassis* ackermann() { return dynamic_cast<AckermannChassis*>(chassis_.get()); }
  DifferentialChassis* differential() { return dynamic_cast<DifferentialChassis*>(chassis_.get()); }

  /// The latest echo: a new one when the sonar's period has passed since
  /// the last, else the last again.
  SonarReading sonar();
  LineReading line_tracker() const;
  /// The tag under the reader now, unless this pass over it is being missed.
  std::optional<std::string> rfid() const;
  /// Tags read so far, counting each pass once.
  std::uint64_t rfid_reads() const { return rfid_reads_; }
  IrReading ir() const;
  const Odometry& odometry() const { return odometry_; }
  BatteryReading battery() const { return battery_.reading(); }

  void set_faults(const SensorFaults& faults) { def_.faults = faults; }
  const SensorFaults& faults() const { return def_.faults; }
  const VehicleDef& def() const { return def_; }

  /// Walls, obstacles and cars touching the chassis now.
  int contacts() const { return contacts_; }

  void hash_state(StateHasher& hasher) const;

 private:
  friend class World;
  Vehicle(World& world, std::size_t index, VehicleDef def);
  void before_step(double dt_s);
  void after_step(double dt_s);
  std::optional<double> cast(Vec2 from, Vec2 to) const override;

  World& world_;
  std::size_t index_;
  std::string name_;
  VehicleDef def_;
  std::unique_ptr<Chassis> chassis_;
  b2Body* body_ = nullptr;
  Battery battery_;
  Random random_;
  Odometry odometry_;
  std::optional<SonarReading> sonar_last_;
  Duration sonar_time_{};
  const RfidTag* tag_under_ = nullptr;
  bool tag_missed_ = false;
  std::uint64_t rfid_reads_ = 0;
  int contacts_ = 0;
};

}  // namespace hil::sim
