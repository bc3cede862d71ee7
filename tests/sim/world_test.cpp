// The world's clock and its determinism: the same arena, seed and commands
// give the same state hash, however the caller slices time.

#include <gtest/gtest.h>

#include <functional>
#include <vector>

#include "sim/presets.hpp"
#include "tests/sim/sim_test_support.hpp"

namespace hil::sim {
namespace {

using test::seconds;

TEST(WorldClock, StepsAreFixedAt120PerSecondWithExactNanosecondEnds) {
  EXPECT_EQ(step_end(1).count(), 8'333'333);
  EXPECT_EQ(step_end(120).count(), 1'000'000'000);
  EXPECT_EQ(step_end(121).count(), 1'008'333'333);
  World world({});
  world.advance_to(seconds(1.0));
  EXPECT_EQ(world.steps(), 120);
  EXPECT_EQ(world.time(), seconds(1.0));
}

TEST(WorldClock, AdvancesShorterThanAStepAccumulate) {
  World world({});
  for (int i = 0; i < 1000; ++i)
    world.advance_by(std::chrono::milliseconds(1));
  EXPECT_EQ(world.steps(), 120);
  world.advance_to(seconds(0.5));  // the past is ignored
  EXPECT_EQ(world.steps(), 120);
}

TEST(WorldDef, AnUnusableArenaIsRefusedWithItsProblems) {
  Arena arena = default_warehouse_arena();
  arena.tags.push_back(arena.tags.front());
  arena.tapes[0].width_m = 0;
  try {
    World world({arena});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("tapes[0]: width must be positive"), std::string::npos) << what;
    EXPECT_NE(what.find("'001' is used twice"), std::string::npos) << what;
  }
}

/// A scripted session on the warehouse: drive, strafe, turn, hit the
/// shelf, with sonar noise and every sensor fault switched on so the random
/// generators are part of the hash.
struct Script {
  std::uint64_t seed = 7;
  std::vector<std::pair<double, std::function<void(Vehicle&)>>> commands = {
      {0.0,
       [](Vehicle& v) {
         v.mecanum()->set_target({0.4, 0, 0});
       }},
      {1.5,
       [](Vehicle& v) {
         v.mecanum()->set_target({0.2, 0.2, 0.5});
       }},
      {3.0,
       [](Vehicle& v) {
         v.mecanum()->set_target({0, 0.4, 0});
       }},
      {6.0,
       [](Vehicle& v) {
         v.mecanum()->set_target({0, 0, -1.0});
       }},
      {7.0, [](Vehicle& v) { v.mecanum()->stop(); }},
  };
};

VehicleDef noisy_logi() {
  VehicleDef def = logi_car();
  def.sonar.noise_stddev_m = 0.01;
  def.faults.sonar_glitch_probability = 0.05;
  def.faults.rfid_miss_probability = 0.5;
  def.faults.wheel_slip_fraction = 0.1;
  return def;
}

/// Runs the script in slices of `slice` and reads the sonar every slice.
std::uint64_t run_script(const Script& script, Duration slice, Duration until) {
  World world({default_warehouse_arena(), script.seed});
  Vehicle& car = world.add_vehicle(noisy_logi());
  std::size_t next = 0;
  for (Duration t{}; t < until;) {
    // Commands land on the first step boundary at or after their time.
    while (next < script.commands.size() && seconds(script.commands[next].first) <= world.time()) {
      script.commands[next++].second(car);
    }
    const Duration target = std::min(until, t + slice);
    // Step one at a time so commands and sonar reads happen on step edges.
    while (step_end(world.steps() + 1) <= target) {
      world.step();
      if (world.steps() % 12 == 0) car.sonar();
      while (next < script.commands.size() &&
             seconds(script.commands[next].first) <= world.time()) {
        script.commands[next++].second(car);
      }
    }
    world.advance_to(target);
    t = target;
  }
  return world.state_hash();
}

TEST(Determinism, SameScriptSameSeedSameHash) {
  const Script script;
  const auto a = run_script(script, seconds(10), seconds(10));
  const auto b = run_script(script, seconds(10), seconds(10));
  EXPECT_EQ(a, b);
}

TEST(Determinism, SlicingTimeDoesNotChangeTheHash) {
  const Script script;
  const auto whole = run_script(script, seconds(10), seconds(10));
  EXPECT_EQ(run_script(script, std::chrono::milliseconds(1), seconds(10)), whole);
  EXPECT_EQ(run_script(script, std::chrono::microseconds(3'700), seconds(10)), whole);
  EXPECT_EQ(run_script(script, std::chrono::milliseconds(333), seconds(10)), whole);
}

TEST(Determinism, TheHashSeesTheSeedAndTheCommands) {
  Script script;
  const auto base = run_script(script, seconds(10), seconds(10));
  Script reseeded;
  reseeded.seed = 8;
  EXPECT_NE(run_script(reseeded, seconds(10), seconds(10)), base);
  Script changed;
  changed.commands[1].first = 1.6;
  EXPECT_NE(run_script(changed, seconds(10), seconds(10)), base);
}

TEST(Determinism, AdvanceToRunsTheSameStepsAsStepping) {
  World a({});
  World b({});
  a.add_vehicle(logi_car()).mecanum()->set_target({0.3, 0.1, 0.2});
  b.add_vehicle(logi_car()).mecanum()->set_target({0.3, 0.1, 0.2});
  a.advance_to(seconds(2.5));
  for (int i = 0; i < 300; ++i)
    b.step();
  EXPECT_EQ(a.steps(), b.steps());
  EXPECT_EQ(a.state_hash(), b.state_hash());
}

TEST(Fleet, CarsCollideWithEachOtherAndSeeEachOtherOnSonar) {
  Arena arena = test::open_field(6.0);
  World world({arena});
  VehicleDef west = logi_car();
  west.name = "west";
  west.start = Pose{2.0, 3.0, 0};
  VehicleDef east = logi_car();
  east.name = "east";
  east.start = Pose{4.0, 3.0, std::numbers::pi};
  Vehicle& a = world.add_vehicle(west);
  Vehicle& b = world.add_vehicle(east);
  // 2 m apart nose to nose: each front is 0.14 m ahead, so 1.72 m between faces.
  EXPECT_NEAR(a.sonar().distance_m, 2.0 - 0.28, 0.01);
  a.mecanum()->set_target({0.3, 0, 0});
  b.mecanum()->set_target({0.3, 0, 0});
  world.advance_by(seconds(5.0));
  const auto contacts = world.take_contacts();
  ASSERT_GE(contacts.size(), 2u);
  EXPECT_EQ(contacts[0].with, ContactEvent::With::vehicle);
  EXPECT_EQ(contacts[0].other_name, contacts[0].vehicle == 0 ? "east" : "west");
  EXPECT_NEAR(b.pose().x_m - a.pose().x_m, 0.28, 0.02);
}

}  // namespace
}  // namespace hil::sim
