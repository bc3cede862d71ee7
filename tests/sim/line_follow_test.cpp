// End to end on the built-in warehouse: a plain proportional line follower,
// fed only by the simulated line tracker and RFID reader, drives the
// mecanum car from the start pose past station 001 to station 002. This is
// what the LOGI firmware's auto mode will stand on.

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <cstdlib>
#include <fstream>

#include "sim/presets.hpp"
#include "sim/recorder.hpp"
#include "sim/svg.hpp"
#include "tests/sim/sim_test_support.hpp"

namespace hil::sim {
namespace {

struct FollowRun {
  std::vector<std::string> stations;  // in the order read
  double seconds_to_002 = -1;
  double worst_offset_m = 0;  // tracker row centre to tape centre line
  double longest_lost_s = 0;
  int contacts = 0;
};

/// Follows the tape to station 002 while the Arduino robot, started below
/// the pillar, drives into it; `recorder` gets both cars' runs.
FollowRun follow_to_002(VehicleDef def, double speed_mps, double gain_radps,
                        TrajectoryRecorder& recorder) {
  World world({default_warehouse_arena(), 5});
  Vehicle& car = world.add_vehicle(def);
  VehicleDef robot = arduino_robot();
  robot.start = Pose{0.3, 1.2, std::numbers::pi / 2};
  Vehicle& other = world.add_vehicle(robot);
  other.differential()->set_pwm(80, 80);
  const Tape& tape = world.arena().tapes.at(0);
  FollowRun run;
  int last_deviation = 0;
  double lost_since = -1;
  // The controller runs every 10 ms on its own clock, as firmware would.
  for (int tick = 0; tick < 60 * 100; ++tick) {
    world.advance_to(std::chrono::milliseconds(10 * tick));
    recorder.observe(world);
    const double now = to_seconds(world.time());
    const LineReading line = car.line_tracker();
    if (line.lost()) {
      if (lost_since < 0) lost_since = now;
      run.longest_lost_s = std::max(run.longest_lost_s, now - lost_since);
    } else {
      lost_since = -1;
      last_deviation = line.deviation;
    }
    // Tape to the right (positive deviation): turn right (clockwise).
    car.mecanum()->set_target({speed_mps, 0, -gain_radps * last_deviation});
    const Vec2 row = car.pose().to_arena({def.line_tracker.ahead_m, 0});
    run.worst_offset_m = std::max(run.worst_offset_m, tape.distance_to_centerline(row));
    if (auto id = car.rfid(); id && (run.stations.empty() || run.stations.back() != *id)) {
      run.stations.push_back(*id);
      if (*id == "002") {
        run.seconds_to_002 = now;
        car.mecanum()->stop();
        break;
      }
    }
  }
  other.differential()->stop();
  for (int tick = 0; tick < 200; ++tick) {
    world.advance_by(std::chrono::milliseconds(10));
    recorder.observe(world);
  }
  for (const auto& mark : recorder.trajectories().at(0).marks)
    if (mark.kind == MarkKind::collision) ++run.contacts;
  EXPECT_NEAR(car.velocity().vx_mps, 0.0, 1e-6) << "the car should be at rest after stopping";
  return run;
}

TEST(LineFollow, TheLogiCarFollowsTheLoopFromStartPast001To002) {
  TrajectoryRecorder recorder;
  const FollowRun run = follow_to_002(logi_car(), 0.25, 1.2, recorder);
  EXPECT_EQ(run.stations, (std::vector<std::string>{"001", "002"}));
  // About 4.7 m of tape at 0.25 m/s, and slower in the bends.
  EXPECT_GT(run.seconds_to_002, 17.0);
  EXPECT_LT(run.seconds_to_002, 25.0);
  EXPECT_LT(run.worst_offset_m, 0.04);
  EXPECT_LT(run.longest_lost_s, 0.3);
  EXPECT_EQ(run.contacts, 0);

  // The robot's run: into the pillar, and at rest against it.
  const Trajectory& robot = recorder.trajectories().at(1);
  ASSERT_GE(robot.marks.size(), 2u);
  EXPECT_EQ(robot.marks[0].kind, MarkKind::collision);
  EXPECT_EQ(robot.marks[0].label, "hit pillar");
  EXPECT_EQ(robot.marks[1].kind, MarkKind::stop);

  // The picture in docs/simulation.md: HIL_WRITE_IMAGES=docs/images writes it.
  SvgOptions options;
  options.title =
      "Built-in warehouse: LOGI car following the tape to 002, Arduino robot into the pillar";
  const std::string svg = render_svg(default_warehouse_arena(), recorder.trajectories(), options);
  EXPECT_NE(svg.find("hit pillar"), std::string::npos);
  if (const char* dir = std::getenv("HIL_WRITE_IMAGES"); dir != nullptr && *dir != '\0') {
    std::ofstream file(std::string(dir) + "/warehouse-run.svg", std::ios::binary);
    file << svg;
    ASSERT_TRUE(file.good());
  }
}

TEST(LineFollow, AMissedRfidReadCarriesTheCarPastTheStation) {
  VehicleDef def = logi_car();
  def.faults.rfid_miss_probability = 1.0;
  World world({default_warehouse_arena()});
  Vehicle& car = world.add_vehicle(def);
  car.mecanum()->set_target({0.25, 0, 0});
  world.advance_by(std::chrono::seconds(5));  // straight over 001 at (2.0, 0.6)
  EXPECT_GT(car.pose().x_m, 2.1);
  EXPECT_EQ(car.rfid_reads(), 0u);
}

}  // namespace
}  // namespace hil::sim
