#pragma once
// A mock Arduino robot under the virtual-time driver with a client on its
// serial port, for the tests of either dialect.

#include <memory>
#include <string>
#include <string_view>

#include "mocks/arduino.hpp"
#include "sim/geometry.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"

namespace hil::mocks::test_arduino {

using Car = test::VirtualCar<ArduinoFirmware>;

inline std::unique_ptr<Car> make_car(ArduinoConfig config = {}, sim::WorldDef world = {}) {
  return std::make_unique<Car>(
      sim::arduino_robot(),
      [config](sim::World& w, sim::Vehicle& v) {
        return std::make_unique<ArduinoFirmware>(w, v, config);
      },
      ServerOptions{}, std::move(world));
}

/// A robot with a client on its serial port.
struct Robot {
  explicit Robot(ArduinoConfig config = {}, sim::WorldDef world = {})
      : car(make_car(std::move(config), std::move(world))), client(car->connect()) {}

  /// Sends `frame` and returns what came back at the same instant.
  std::string ask(std::string_view frame) {
    client->write(frame);
    car->run_for(Duration::zero());
    return client->take_text();
  }
  ArduinoFirmware& firmware() { return car->firmware(); }
  const ArduinoState& state() { return car->firmware().state(); }
  sim::DifferentialChassis& chassis() { return *car->vehicle().differential(); }
  sim::Pose pose() { return car->vehicle().pose(); }
  Time now() const { return car->now(); }
  void run_until(Time t) { car->run_until(t); }
  void run_for(Duration d) { car->run_for(d); }
  /// What STATUS answers at `now`, as the firmware would write it.
  std::string status_at(Time now) { return car->firmware().status_text(now); }

  std::unique_ptr<Car> car;
  std::shared_ptr<test::ClientEnd> client;
};

/// A 12 m by 12 m arena with nothing in it, the robot in its middle: no
/// echo ever comes back to the sonar.
inline sim::WorldDef open_field() {
  sim::WorldDef world;
  world.arena.width_m = 12;
  world.arena.height_m = 12;
  world.arena.obstacles.clear();
  world.arena.tapes.clear();
  world.arena.tags.clear();
  world.arena.start = sim::Pose{6, 6, 0};
  return world;
}

inline double heading_deg(const sim::Pose& pose) {
  return sim::rad_to_deg(pose.heading_rad);
}

}  // namespace hil::mocks::test_arduino
