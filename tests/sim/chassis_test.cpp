// Kinematic self-tests: each chassis, commanded at the wheels, moves the
// Box2D body as the textbook formulas say, measured from the pose the
// physics reports once the motors are at speed.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/presets.hpp"
#include "tests/sim/sim_test_support.hpp"

namespace hil::sim {
namespace {

using test::open_field;
using test::seconds;
using test::starting_at;

constexpr double kTolerance = 0.01;  // 1 % of the expected value once at speed

/// Arena-frame displacement and heading change over `duration`, after a
/// spin-up of one second.
struct Motion {
  Vec2 moved_body;    // displacement in the body frame at the start of the window
  double turned_rad;  // heading change (unwrapped)
  double seconds;
};

Motion measure(World& world, Vehicle& car, double window_s) {
  world.advance_by(seconds(1.0));
  const Pose before = car.pose();
  double turned = 0;
  double last = before.heading_rad;
  const int steps = static_cast<int>(window_s * kStepsPerSecond);
  for (int i = 0; i < steps; ++i) {
    world.step();
    const double now = car.pose().heading_rad;
    turned += wrap_angle(now - last);
    last = now;
  }
  const Pose after = car.pose();
  return {rotate(after.position() - before.position(), -before.heading_rad), turned, window_s};
}

/// How a mecanum car moves over two seconds with its wheels turning at
/// `targets` (rad/s).
Motion mecanum_motion(const MecanumWheels& targets) {
  World world({open_field()});
  Vehicle& car = world.add_vehicle(starting_at(logi_car(), Pose{20, 20, 0.3}));
  car.mecanum()->set_wheel_targets(targets);
  return measure(world, car, 2.0);
}

TEST(MecanumKinematics, InverseThenForwardIsIdentity) {
  const MecanumDef def;
  const Twist twist{0.3, -0.2, 0.7};
  const Twist back =
      MecanumChassis::forward_kinematics(def, MecanumChassis::inverse_kinematics(def, twist));
  EXPECT_NEAR(back.vx_mps, twist.vx_mps, 1e-12);
  EXPECT_NEAR(back.vy_mps, twist.vy_mps, 1e-12);
  EXPECT_NEAR(back.wz_radps, twist.wz_radps, 1e-12);
}

TEST(MecanumKinematics, ForwardAndStrafeGoStraightAtWheelSurfaceSpeedWithoutTurning) {
  const double w = 8.0;  // rad/s
  const double r = MecanumDef{}.wheel_radius_m;
  struct Case {
    const char* what;
    MecanumWheels wheels;
    bool sideways;  // the car goes left rather than forwards
  };
  const Case cases[] = {
      {"all wheels forward", {w, w, w, w}, false},
      // Textbook strafe: front-left and rear-right backwards, the other two forwards.
      {"crossed wheels strafe left", {-w, w, w, -w}, true},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const Motion m = mecanum_motion(c.wheels);
    const double along = c.sideways ? m.moved_body.y_m : m.moved_body.x_m;
    const double across = c.sideways ? m.moved_body.x_m : m.moved_body.y_m;
    EXPECT_NEAR(along / m.seconds, r * w, kTolerance * r * w);
    EXPECT_NEAR(across, 0.0, 1e-3);
    EXPECT_NEAR(m.turned_rad, 0.0, 1e-3);
  }
}

TEST(MecanumKinematics, OpposedSidesTurnInPlaceAtROverLxPlusLy) {
  const double w = 8.0;
  const Motion m = mecanum_motion({-w, w, -w, w});
  const MecanumDef def;
  const double expected = def.wheel_radius_m * w / (def.half_wheelbase_m + def.half_track_m);
  EXPECT_NEAR(m.turned_rad / m.seconds, expected, kTolerance * expected);
  EXPECT_NEAR(length(m.moved_body), 0.0, 1e-3);
}

TEST(MecanumKinematics, OneDiagonalPairMovesAtFortyFiveDegrees) {
  const double w = 8.0;
  const Motion m = mecanum_motion({0, w, w, 0});  // front-right and rear-left: forward-left
  const double r = MecanumDef{}.wheel_radius_m;
  EXPECT_NEAR(m.moved_body.x_m / m.seconds, r * w / 2, kTolerance * r * w / 2);
  EXPECT_NEAR(m.moved_body.y_m / m.seconds, r * w / 2, kTolerance * r * w / 2);
}

TEST(MecanumChassis, SpeedPercentMapsToTopSpeedAndRampsAtTheAccelerationLimit) {
  MecanumChassis chassis{MecanumDef{}};
  EXPECT_DOUBLE_EQ(chassis.speed_for_percent_mps(100), 0.5);
  EXPECT_DOUBLE_EQ(chassis.speed_for_percent_mps(50), 0.25);
  EXPECT_DOUBLE_EQ(chassis.speed_for_percent_mps(140), 0.5);
  chassis.set_target({0.5, 0, 0});
  // 1 m/s^2: after 0.25 s the car does 0.25 m/s, full speed after 0.5 s.
  for (int i = 0; i < 30; ++i)
    chassis.update(kStepSeconds);
  EXPECT_NEAR(chassis.wheel_twist().vx_mps, 0.25, 1e-9);
  for (int i = 0; i < 30; ++i)
    chassis.update(kStepSeconds);
  EXPECT_NEAR(chassis.wheel_twist().vx_mps, 0.5, 1e-9);
}

TEST(MecanumChassis, TargetsPastTheTopWheelSpeedAreScaledAsAWhole) {
  MecanumChassis chassis{MecanumDef{}};
  chassis.set_target({1.0, 1.0, 0});
  const Twist t = chassis.target();
  EXPECT_DOUBLE_EQ(t.vx_mps, t.vy_mps);  // direction kept
  const MecanumWheels w = MecanumChassis::inverse_kinematics(MecanumDef{}, t);
  EXPECT_NEAR(std::abs(w.front_right_radps), chassis.max_wheel_radps(), 1e-9);
}

TEST(MecanumChassis, MotorRpmIsReportedInTheFirmwareOrderLrLfRfRr) {
  MecanumChassis chassis{MecanumDef{}};
  // Distinct speeds per wheel: forward plus a left turn.
  chassis.set_wheel_targets({1.0, 2.0, 3.0, 4.0});
  for (int i = 0; i < 240; ++i)
    chassis.update(kStepSeconds);
  const auto w = chassis.wheels();
  const auto rpm = chassis.motor_rpm();
  const double k = 60.0 / (2 * std::numbers::pi);
  EXPECT_NEAR(rpm[0], w.rear_left_radps * k, 1e-9);
  EXPECT_NEAR(rpm[1], w.front_left_radps * k, 1e-9);
  EXPECT_NEAR(rpm[2], w.front_right_radps * k, 1e-9);
  EXPECT_NEAR(rpm[3], w.rear_right_radps * k, 1e-9);
}

TEST(AckermannKinematics, SteadyTurnFollowsTheBicycleModelRadius) {
  World world({open_field()});
  Vehicle& car = world.add_vehicle(starting_at(wr8_vehicle(), Pose{20, 20, 0}));
  AckermannChassis& chassis = *car.ackermann();
  const double steer = 0.35;  // rad
  const double v = 0.6;       // m/s
  chassis.set_steering_target(steer);
  chassis.set_speed_target(v);
  const Motion m = measure(world, car, 3.0);
  const double L = AckermannDef{}.wheelbase_m;
  const double expected_rate = v * std::tan(steer) / L;
  EXPECT_NEAR(m.turned_rad / m.seconds, expected_rate, kTolerance * expected_rate);
  // The rear axle's midpoint stays on a circle of radius L / tan(steer).
  const double chord = length(m.moved_body);
  const double expected_chord = 2 * (L / std::tan(steer)) * std::sin(std::abs(m.turned_rad) / 2);
  EXPECT_NEAR(chord, expected_chord, kTolerance * expected_chord);
}

TEST(AckermannChassis, SteeringIsClampedAndSlewsAtItsRate) {
  AckermannChassis chassis{AckermannDef{}};
  chassis.set_steering_target(1.0);
  EXPECT_DOUBLE_EQ(chassis.steering_target_rad(), AckermannDef{}.max_steering_rad);
  chassis.update(0.1);
  EXPECT_NEAR(chassis.steering_rad(), AckermannDef{}.steering_rate_radps * 0.1, 1e-12);
  for (int i = 0; i < 10; ++i)
    chassis.update(0.1);
  EXPECT_DOUBLE_EQ(chassis.steering_rad(), AckermannDef{}.max_steering_rad);
}

TEST(AckermannChassis, DrivesACommandedDistanceAndStopsOnIt) {
  World world({open_field()});
  Vehicle& car = world.add_vehicle(starting_at(wr8_vehicle(), Pose{10, 20, 0}));
  const Pose start = car.pose();
  car.ackermann()->drive_distance(1.0, 0.5);
  world.advance_by(seconds(1.0));
  EXPECT_TRUE(car.ackermann()->driving_distance());
  world.advance_by(seconds(4.0));
  EXPECT_FALSE(car.ackermann()->driving_distance());
  EXPECT_NEAR(car.ackermann()->speed_mps(), 0.0, 1e-9);
  EXPECT_NEAR(car.ackermann()->odometer_m(), 1.0, 0.002);
  EXPECT_NEAR(car.pose().x_m - start.x_m, 1.0, 0.005);
  EXPECT_NEAR(car.odometry().distance_m, 1.0, 0.002);
}

TEST(AckermannChassis, DrivesBackwardsForANegativeDistance) {
  AckermannChassis chassis{AckermannDef{}};
  chassis.drive_distance(-0.3, 0.4);
  for (int i = 0; i < 600 && chassis.driving_distance(); ++i)
    chassis.update(kStepSeconds);
  EXPECT_FALSE(chassis.driving_distance());
  EXPECT_NEAR(chassis.odometer_m(), 0.3, 0.002);
}

TEST(DifferentialKinematics, UnequalSidesFollowTheDifferentialDriveFormulas) {
  World world({open_field()});
  Vehicle& car = world.add_vehicle(starting_at(arduino_robot(), Pose{20, 20, 1.0}));
  car.differential()->set_pwm(100, 160);
  const Motion m = measure(world, car, 2.0);
  const DifferentialDef d;
  const double vl = 100 * d.speed_per_pwm_mps;
  const double vr = 160 * d.speed_per_pwm_mps;
  const double w = (vr - vl) / d.effective_track_m;
  EXPECT_NEAR(m.turned_rad / m.seconds, w, kTolerance * w);
  const double radius = (vl + vr) / 2 / w;
  const double expected_chord = 2 * radius * std::sin(m.turned_rad / 2);
  EXPECT_NEAR(length(m.moved_body), expected_chord, kTolerance * expected_chord);
}

TEST(DifferentialChassis, ArduinoTimedMovesLandOnTheirTargetsAtBasePwm) {
  // The firmware drives M:50 for 50 * 18 ms and R:90 for 90 * 6 ms at PWM 140.
  World world({open_field()});
  Vehicle& car = world.add_vehicle(starting_at(arduino_robot(), Pose{20, 20, 0}));
  car.differential()->set_pwm(140, 140);
  world.advance_by(std::chrono::milliseconds(50 * 18));
  car.differential()->set_pwm(0, 0);
  world.advance_by(seconds(1.0));
  EXPECT_NEAR(car.pose().x_m - 20, 0.50, 0.01);

  const double heading = car.pose().heading_rad;
  car.differential()->set_pwm(140, -140);  // right turn: "+" is right in R
  world.advance_by(std::chrono::milliseconds(90 * 6));
  car.differential()->set_pwm(0, 0);
  world.advance_by(seconds(1.0));
  EXPECT_NEAR(rad_to_deg(wrap_angle(car.pose().heading_rad - heading)), -90.0, 2.0);
}

TEST(DifferentialChassis, PwmIsClampedToItsRange) {
  DifferentialChassis chassis{DifferentialDef{}};
  chassis.set_pwm(300, -999);
  EXPECT_EQ(chassis.left_pwm(), 255);
  EXPECT_EQ(chassis.right_pwm(), -255);
}

TEST(Collisions, AWallStopsTheChassisAndIsReportedOnce) {
  World world({open_field(4.0)});
  Vehicle& car = world.add_vehicle(starting_at(logi_car(), Pose{2.0, 2.0, 0}));
  car.mecanum()->set_target({0.5, 0, 0});
  world.advance_by(seconds(8.0));
  // Pressed against the east wall: at rest there, the wheels still turning.
  EXPECT_NEAR(car.pose().x_m, 4.0 - 0.14, 0.02);
  EXPECT_NEAR(car.velocity().vx_mps, 0.0, 0.01);
  EXPECT_NEAR(car.mecanum()->wheel_twist().vx_mps, 0.5, 1e-9);
  const auto contacts = world.take_contacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].phase, ContactEvent::Phase::begin);
  EXPECT_EQ(contacts[0].with, ContactEvent::With::wall);
  EXPECT_NEAR(contacts[0].point_m.x_m, 4.0, 0.02);
  // Reached at 2 - 0.14 m of travel: 0.25 m to speed up, then 0.5 m/s.
  EXPECT_NEAR(to_seconds(contacts[0].time), 0.5 + (1.86 - 0.125) / 0.5, 0.05);
  EXPECT_EQ(car.contacts(), 1);
}

TEST(Collisions, AnAngledWallDeflectsTheChassisAlongIt) {
  World world({open_field(4.0)});
  // Heading 29 degrees, toward the east wall.
  Vehicle& car = world.add_vehicle(starting_at(logi_car(), Pose{2.0, 2.0, 0.5}));
  car.mecanum()->set_target({0.4, 0, 0});
  world.advance_by(seconds(5.0));
  const Pose p = car.pose();
  // It slides north along the wall rather than stopping dead.
  EXPECT_GT(p.y_m, 2.6);
  EXPECT_GT(car.velocity().vx_mps * std::sin(p.heading_rad), 0.05);
}

TEST(Collisions, ObstacleContactsNameTheObstacleAndEnd) {
  Arena arena = open_field(4.0);
  arena.obstacles.push_back(CircleObstacle{"pillar", {3.0, 2.0}, 0.1});
  World world({arena});
  Vehicle& car = world.add_vehicle(starting_at(logi_car(), Pose{2.0, 2.0, 0}));
  car.mecanum()->set_target({0.3, 0, 0});
  world.advance_by(seconds(4.0));
  car.mecanum()->set_target({-0.3, 0, 0});
  world.advance_by(seconds(1.0));
  const auto contacts = world.take_contacts();
  ASSERT_EQ(contacts.size(), 2u);
  EXPECT_EQ(contacts[0].with, ContactEvent::With::obstacle);
  EXPECT_EQ(contacts[0].other_name, "pillar");
  EXPECT_EQ(contacts[0].phase, ContactEvent::Phase::begin);
  EXPECT_EQ(contacts[1].phase, ContactEvent::Phase::end);
  EXPECT_EQ(car.contacts(), 0);
}

}  // namespace
}  // namespace hil::sim
