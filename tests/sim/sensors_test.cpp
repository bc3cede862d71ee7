// Sensors read the arena as the real ones would, and their faults do what
// their options say.

#include <gtest/gtest.h>

#include <numbers>

#include "sim/presets.hpp"
#include "tests/sim/sim_test_support.hpp"

namespace hil::sim {
namespace {

using test::open_field;
using test::seconds;
using test::starting_at;

TEST(Sonar, MeasuresTheDistanceFromItsMountToTheWallAhead) {
  World world({open_field(4.0)});
  Vehicle& car = world.add_vehicle(starting_at(logi_car(), Pose{1.0, 2.0, 0}));
  // Mount 0.14 m ahead of the centre; wall face at x = 4.
  const SonarReading r = car.sonar();
  EXPECT_TRUE(r.echo);
  EXPECT_NEAR(r.distance_m, 4.0 - 1.14, 1e-4);
  EXPECT_EQ(r.distance_cm(), 286);
}

TEST(Sonar, TheConeSeesAPillarOffTheAxis) {
  Arena arena = open_field(6.0);
  arena.obstacles.push_back(CircleObstacle{"pillar", {2.0, 3.2}, 0.05});
  World world({arena});
  VehicleDef def = starting_at(logi_car(), Pose{1.0, 3.0, 0});
  Vehicle& car = world.add_vehicle(def);
  // 10 to 16 degrees off the axis: only the cone's edge ray finds it.
  const double d = car.sonar().distance_m;
  EXPECT_LT(d, 1.0);
  EXPECT_GT(d, 0.75);
  def.sonar.rays = 1;  // axis only: the far wall, 4.86 m away, is past the range
  World narrow({arena});
  const SonarReading axis_only = narrow.add_vehicle(def).sonar();
  EXPECT_FALSE(axis_only.echo);
  EXPECT_DOUBLE_EQ(axis_only.distance_m, 4.0);
}

TEST(Sonar, ReadsMaxRangeWithoutAnEchoAndClampsToMinRange) {
  World world({open_field(20.0)});
  VehicleDef def = logi_car();
  def.start = Pose{2.0, 10.0, 0};
  const SonarReading far = world.add_vehicle(def).sonar();
  EXPECT_FALSE(far.echo);
  EXPECT_DOUBLE_EQ(far.distance_m, 4.0);
  World close({open_field(4.0)});
  def.start = Pose{4.0 - 0.15, 2.0, 0};  // 1 cm from the wall
  EXPECT_DOUBLE_EQ(close.add_vehicle(def).sonar().distance_m, 0.02);
}

TEST(Sonar, NoiseIsSeededAndCentredOnTheTruth) {
  World world({open_field(4.0), 42});
  VehicleDef def = logi_car();
  def.start = Pose{1.0, 2.0, 0};
  def.sonar.noise_stddev_m = 0.02;
  def.sonar.period_s = 0;  // a fresh echo on every read
  Vehicle& car = world.add_vehicle(def);
  double sum = 0;
  double sum2 = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const double e = car.sonar().distance_m - 2.86;
    sum += e;
    sum2 += e * e;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.002);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.02, 0.002);
  World again({open_field(4.0), 42});
  Vehicle& twin = again.add_vehicle(def);
  World other({open_field(4.0), 43});
  Vehicle& stranger = other.add_vehicle(def);
  World first({open_field(4.0), 42});
  const double a = first.add_vehicle(def).sonar().distance_m;
  EXPECT_DOUBLE_EQ(twin.sonar().distance_m, a);
  EXPECT_NE(stranger.sonar().distance_m, a);
}

TEST(SensorFaults, SonarGlitchesAtTheirProbabilityWithTheirValue) {
  World world({open_field(4.0), 3});
  VehicleDef def = logi_car();
  def.start = Pose{1.0, 2.0, 0};
  def.faults.sonar_glitch_probability = 0.2;
  def.faults.sonar_glitch_m = 0.0;
  def.sonar.period_s = 0;
  Vehicle& car = world.add_vehicle(def);
  int glitches = 0;
  for (int i = 0; i < 5000; ++i) {
    const SonarReading r = car.sonar();
    if (r.glitch) {
      ++glitches;
      EXPECT_EQ(r.distance_cm(), 0);
    } else {
      EXPECT_EQ(r.distance_cm(), 286);
    }
  }
  EXPECT_NEAR(glitches / 5000.0, 0.2, 0.02);
}

TEST(Sonar, ANewEchoComesOncePerPeriod) {
  World world({open_field(4.0), 9});
  VehicleDef def = logi_car();
  def.start = Pose{1.0, 2.0, 0};
  def.sonar.noise_stddev_m = 0.05;
  Vehicle& car = world.add_vehicle(def);
  const double first = car.sonar().distance_m;
  EXPECT_EQ(car.sonar().distance_m, first);  // same instant: the same echo
  world.advance_by(std::chrono::milliseconds(50));
  EXPECT_EQ(car.sonar().distance_m, first);         // 50 ms < 60 ms
  world.advance_by(std::chrono::milliseconds(10));  // the world is at step 7, 58.3 ms
  EXPECT_EQ(car.sonar().distance_m, first);
  world.advance_by(std::chrono::milliseconds(10));  // step 8, 66.7 ms
  EXPECT_NE(car.sonar().distance_m, first);         // a new ping, new noise
}

TEST(LineTracker, MaskAndDeviationFollowTheTapeAcrossTheRow) {
  Arena arena = open_field(4.0);
  arena.tapes.push_back(Tape{"line", {{0.5, 2.0}, {3.5, 2.0}}, 0.03, false});
  World world({arena});
  VehicleDef def = logi_car();
  // Centred: H3 and H2 on tape.
  struct Case {
    double car_y_m;  // the tape is at y = 2; the car faces +x, so +y is its left
    std::uint8_t mask;
    int deviation;
  };
  const Case cases[] = {
      {2.000, 0b0110, 0},  {2.020, 0b0010, 1},  {2.024, 0b0011, 2},  {2.040, 0b0001, 3},
      {1.980, 0b0100, -1}, {1.976, 0b1100, -2}, {1.955, 0b1000, -3}, {2.100, 0b0000, 0},
  };
  for (const auto& c : cases) {
    World w({arena});
    def.start = Pose{1.0, c.car_y_m, 0};
    const LineReading r = w.add_vehicle(def).line_tracker();
    EXPECT_EQ(r.mask, c.mask) << "car at y = " << c.car_y_m;
    EXPECT_EQ(r.deviation, c.deviation) << "car at y = " << c.car_y_m;
    EXPECT_EQ(r.lost(), c.mask == 0);
  }
}

TEST(LineTracker, TheBuiltInLoopIsUnderTheCarAtTheStartPose) {
  World world({});
  const LineReading r = world.add_vehicle(logi_car()).line_tracker();
  EXPECT_EQ(r.mask, 0b0110);
  EXPECT_EQ(r.deviation, 0);
}

TEST(Rfid, ReadsTheTagUnderTheReaderOncePerPass) {
  World world({});  // the warehouse: tag 001 at (2.0, 0.6), start at (1.2, 0.6)
  Vehicle& car = world.add_vehicle(logi_car());
  EXPECT_FALSE(car.rfid());
  car.mecanum()->set_target({0.2, 0, 0});
  std::vector<std::string> seen;
  for (int i = 0; i < 6 * 120; ++i) {
    world.step();
    if (auto id = car.rfid(); id && (seen.empty() || seen.back() != *id)) seen.push_back(*id);
  }
  EXPECT_EQ(seen, std::vector<std::string>{"001"});
  EXPECT_EQ(car.rfid_reads(), 1u);
}

TEST(SensorFaults, RfidMissesWholePassesAtTheirProbability) {
  // Back and forth over tag 001 a hundred times.
  Arena arena = open_field(4.0);
  arena.tags.push_back(RfidTag{"001", {2.0, 2.0}, 0.05});
  World world({arena, 11});
  VehicleDef def = logi_car();
  def.start = Pose{1.8, 2.0, 0};
  def.faults.rfid_miss_probability = 0.3;
  Vehicle& car = world.add_vehicle(def);
  int passes = 0;
  for (int i = 0; i < 100; ++i) {
    car.place(Pose{i % 2 == 0 ? 1.8 : 2.2, 2.0, 0});
    car.mecanum()->set_target({i % 2 == 0 ? 0.4 : -0.4, 0, 0});
    for (int s = 0; s < 180; ++s)
      world.step();
    ++passes;
  }
  EXPECT_EQ(passes, 100);
  EXPECT_NEAR(static_cast<double>(car.rfid_reads()), 70.0, 12.0);
  EXPECT_LT(car.rfid_reads(), 100u);
}

TEST(Ir, AnalogRisesAndDigitalTripsAsAnObstacleNears) {
  Arena arena = open_field(4.0);
  arena.obstacles.push_back(BoxObstacle{"crate", {2.0, 2.15}, 0.1, 0.1, 0});
  World world({arena});
  Vehicle& car = world.add_vehicle(starting_at(arduino_robot(), Pose{1.4, 2.0, 0}));
  const IrReading far = car.ir();
  EXPECT_EQ(far.left_analog, 0);
  EXPECT_FALSE(far.left_obstacle);
  EXPECT_FALSE(far.right_obstacle);
  car.place(Pose{1.75, 2.0, 0});
  const IrReading near = car.ir();
  EXPECT_GT(near.left_analog, 400);
  EXPECT_TRUE(near.left_obstacle);
  EXPECT_FALSE(near.right_obstacle);  // the crate is on the left
  EXPECT_EQ(near.right_analog, 0);
}

TEST(Odometry, WheelSlipMakesTheWheelsOverstateTheDistance) {
  World world({open_field(10.0)});
  VehicleDef def = logi_car();
  def.start = Pose{2.0, 5.0, 0};
  def.faults.wheel_slip_fraction = 0.2;
  Vehicle& car = world.add_vehicle(def);
  car.mecanum()->set_target({0.5, 0, 0});
  world.advance_by(seconds(4.0));
  const double truth = car.pose().x_m - 2.0;
  EXPECT_NEAR(car.odometry().distance_m * 0.8, truth, 0.005);
  EXPECT_NEAR(car.odometry().pose.x_m - 2.0, car.odometry().distance_m, 1e-6);
}

TEST(Odometry, DeadReckoningMatchesTheTruthWithoutSlipOrContacts) {
  World world({open_field(10.0)});
  Vehicle& car = world.add_vehicle(starting_at(logi_car(), Pose{5.0, 5.0, 0.4}));
  car.mecanum()->set_target({0.3, 0.1, 0.6});
  world.advance_by(seconds(6.0));
  const Pose truth = car.pose();
  const Pose est = car.odometry().pose;
  EXPECT_NEAR(est.x_m, truth.x_m, 0.01);
  EXPECT_NEAR(est.y_m, truth.y_m, 0.01);
  EXPECT_NEAR(wrap_angle(est.heading_rad - truth.heading_rad), 0.0, 0.01);
}

TEST(Battery, DrainsFasterUnderLoadAndSagsWithCurrent) {
  World idle_world({open_field(40.0)});
  World busy_world({open_field(40.0)});
  const VehicleDef def = starting_at(logi_car(), Pose{5.0, 20.0, 0});
  Vehicle& idle = idle_world.add_vehicle(def);
  Vehicle& busy = busy_world.add_vehicle(def);
  busy.mecanum()->set_target({0, 0, 3.0});  // spin in place: every wheel near full speed
  idle_world.advance_by(seconds(60));
  busy_world.advance_by(seconds(60));
  const BatteryReading a = idle.battery();
  const BatteryReading b = busy.battery();
  // Idle: 0.15 A for 60 s of a 2200 mAh pack.
  EXPECT_NEAR(1.0 - a.charge, 0.15 * 60 / 3600 / 2.2, 1e-6);
  EXPECT_GT(1.0 - b.charge, 5 * (1.0 - a.charge));
  EXPECT_LT(b.voltage_v, a.voltage_v - 0.3);
  EXPECT_EQ(a.percent(), 100);
}

TEST(SensorFaults, BatterySagTakesVoltsOffTheTerminal) {
  World world({});
  Vehicle& car = world.add_vehicle(logi_car());
  world.step();
  const double before = car.battery().voltage_v;
  SensorFaults faults;
  faults.battery_sag_v = 1.5;
  car.set_faults(faults);
  world.step();
  EXPECT_NEAR(car.battery().voltage_v, before - 1.5, 1e-3);
}

}  // namespace
}  // namespace hil::sim
