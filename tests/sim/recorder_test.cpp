// The recorder turns a run into a trajectory with the marks a report shows.

#include <gtest/gtest.h>

#include "sim/presets.hpp"
#include "sim/recorder.hpp"
#include "tests/sim/sim_test_support.hpp"

namespace hil::sim {
namespace {

TEST(TrajectoryRecorder, SamplesAtItsPeriodAndMarksStationCollisionAndStop) {
  World world({});  // the warehouse; start (1.2, 0.6) heading east, tag 001 at (2.0, 0.6)
  Vehicle& car = world.add_vehicle(logi_car());
  TrajectoryRecorder recorder(std::chrono::milliseconds(100));
  car.mecanum()->set_target({0.5, 0, 0});
  for (int ms = 0; ms <= 8000; ms += 10) {
    world.advance_to(std::chrono::milliseconds(ms));
    recorder.observe(world);
  }
  const Trajectory& t = recorder.trajectories().at(0);
  EXPECT_EQ(t.vehicle, "logi");
  ASSERT_EQ(t.samples.size(), 81u);
  EXPECT_EQ(t.samples[10].time, std::chrono::milliseconds(1000));
  EXPECT_NEAR(t.samples.front().pose.x_m, 1.2, 1e-6);  // Box2D keeps poses in floats
  EXPECT_NEAR(t.samples.front().pose.y_m, 0.6, 1e-6);

  std::vector<MarkKind> kinds;
  for (const auto& m : t.marks)
    kinds.push_back(m.kind);
  // Over tag 001, then into the east wall, where it comes to rest.
  ASSERT_EQ(kinds, (std::vector<MarkKind>{MarkKind::station, MarkKind::collision, MarkKind::stop}));
  EXPECT_EQ(t.marks[0].label, "001");
  EXPECT_NEAR(t.marks[0].position_m.x_m, 2.0 - 0.05, 0.01);
  EXPECT_EQ(t.marks[1].label, "hit wall");
  EXPECT_NEAR(t.marks[1].position_m.x_m, 4.0, 0.02);
  EXPECT_LE(t.marks[1].time, t.marks[2].time);
}

TEST(TrajectoryRecorder, NotesLandAtTheCarsPosition) {
  World world({});
  world.add_vehicle(logi_car());
  TrajectoryRecorder recorder;
  recorder.note(world, 0, "MD:AUTO");
  const auto& marks = recorder.trajectories().at(0).marks;
  ASSERT_EQ(marks.size(), 1u);
  EXPECT_EQ(marks[0].kind, MarkKind::note);
  EXPECT_NEAR(marks[0].position_m.x_m, 1.2, 1e-6);
  EXPECT_NEAR(marks[0].position_m.y_m, 0.6, 1e-6);
}

}  // namespace
}  // namespace hil::sim
