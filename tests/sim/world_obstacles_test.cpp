// Obstacles put into and taken out of a running world (a parcel dropped in
// a car's path): the sonar sees them, cars bump into them, and they leave
// no trace once taken out.

#include <gtest/gtest.h>

#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/sim/sim_test_support.hpp"

namespace hil::sim {
namespace {

using test::open_field;
using test::seconds;

VehicleDef quiet_logi() {
  VehicleDef def = logi_car();
  def.sonar.noise_stddev_m = 0;
  return def;
}

TEST(WorldObstacles, TheSonarSeesADroppedParcelAndStopsSeeingItWhenLifted) {
  World world(WorldDef{open_field(), 1});
  Vehicle& car = world.add_vehicle(quiet_logi());
  world.advance_by(seconds(0.1));
  EXPECT_EQ(car.sonar().distance_cm(), 400);  // nothing within range
  const Vec2 ahead = car.pose().to_arena({0.14 + 0.30 + 0.05, 0});
  const std::size_t parcel = world.add_obstacle(BoxObstacle{"parcel", ahead, 0.1, 0.3, 0});
  EXPECT_TRUE(world.obstacle_present(parcel));
  world.advance_by(seconds(0.1));
  EXPECT_EQ(car.sonar().distance_cm(), 30);
  EXPECT_TRUE(world.remove_obstacle(parcel));
  EXPECT_FALSE(world.obstacle_present(parcel));
  EXPECT_FALSE(world.remove_obstacle(parcel));
  world.advance_by(seconds(0.1));
  EXPECT_EQ(car.sonar().distance_cm(), 400);
  EXPECT_EQ(world.arena().obstacles.size(), 1u);  // indices never move
}

TEST(WorldObstacles, ACarDrivingIntoADroppedParcelIsStoppedAndToldWhatItHit) {
  World world(WorldDef{open_field(), 1});
  Vehicle& car = world.add_vehicle(logi_car());
  const Pose start = car.pose();
  world.add_obstacle(CircleObstacle{"crate", start.to_arena({0.5, 0}), 0.1});
  car.mecanum()->set_target({0.3, 0, 0});
  world.advance_by(seconds(4));
  EXPECT_LT(car.pose().x_m - start.x_m, 0.5);
  const auto contacts = world.take_contacts();
  ASSERT_FALSE(contacts.empty());
  EXPECT_EQ(contacts.front().with, ContactEvent::With::obstacle);
  EXPECT_EQ(contacts.front().other_name, "crate");
}

TEST(WorldObstacles, LiftingAParcelACarTouchesEndsTheContactAndLetsItGo) {
  World world(WorldDef{open_field(), 1});
  Vehicle& car = world.add_vehicle(logi_car());
  const Pose start = car.pose();
  const auto crate = world.add_obstacle(CircleObstacle{"crate", start.to_arena({0.5, 0}), 0.1});
  car.mecanum()->set_target({0.3, 0, 0});
  world.advance_by(seconds(3));
  ASSERT_EQ(car.contacts(), 1);
  world.take_contacts();
  world.remove_obstacle(crate);
  EXPECT_EQ(car.contacts(), 0);
  const auto ended = world.take_contacts();
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended.front().phase, ContactEvent::Phase::end);
  const double stuck_x = car.pose().x_m;
  world.advance_by(seconds(1));
  EXPECT_GT(car.pose().x_m - stuck_x, 0.2);
}

TEST(WorldObstacles, ObstaclesArePartOfTheStateHashAndNeedASize) {
  World a(WorldDef{open_field(), 1});
  World b(WorldDef{open_field(), 1});
  const auto index = a.add_obstacle(BoxObstacle{"p", {1, 1}, 0.1, 0.1, 0});
  EXPECT_NE(a.state_hash(), b.state_hash());
  a.remove_obstacle(index);
  EXPECT_NE(a.state_hash(), b.state_hash());  // a parcel came and went
  EXPECT_THROW(a.add_obstacle(BoxObstacle{"flat", {1, 1}, 0.1, 0, 0}), std::invalid_argument);
  EXPECT_THROW(a.add_obstacle(CircleObstacle{"dot", {1, 1}, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace hil::sim
