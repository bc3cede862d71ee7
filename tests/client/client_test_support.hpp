#pragma once
// The virtual-time bench the client session and operator tests share: the
// driver, a world with one mock car, its firmware and the mock server on a
// mem:// endpoint, and running the executor until something happened.

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "link/endpoint.hpp"
#include "link/executor.hpp"
#include "link/time.hpp"
#include "link/transport.hpp"
#include "mocks/server.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"

namespace hil::client::test {

/// A mock car in virtual time. Empty until start_car(); a fixture derives
/// from it or holds one before its session, so the session goes first.
template <class Firmware>
struct VirtualCar {
  /// Puts `vehicle` in a fresh world, runs `Firmware(world, vehicle,
  /// firmware_args...)` behind a mock server with `options`, and starts it.
  template <class... FirmwareArgs>
  void start_car(sim::VehicleDef vehicle, mocks::ServerOptions options,
                 FirmwareArgs&&... firmware_args) {
    world.emplace(sim::WorldDef{});
    sim::Vehicle& v = world->add_vehicle(std::move(vehicle));
    firmware = std::make_unique<Firmware>(*world, v, std::forward<FirmwareArgs>(firmware_args)...);
    server = std::make_unique<mocks::MockServer>(context, *firmware, std::move(options));
    server->start();
  }

  link::VirtualExecutor executor;
  link::TransportContext context{executor};
  std::optional<sim::World> world;
  std::unique_ptr<Firmware> firmware;
  std::unique_ptr<mocks::MockServer> server;
};

/// `options` listening on mem://<name>.
inline mocks::ServerOptions on_mem(const std::string& name, mocks::ServerOptions options = {}) {
  options.listen = link::MemEndpoint{name};
  return options;
}

/// Runs the executor from one due time to the next until `done()` holds or
/// nothing is due within `limit`; whether `done()` held.
template <class Done>
bool run_until_done(link::VirtualExecutor& executor, Done done, link::Duration limit) {
  const link::Time end = executor.now() + limit;
  while (!done() && executor.now() < end) {
    const auto due = executor.next_due();
    if (!due || *due > end) break;
    executor.run_until(*due);
  }
  return done();
}

}  // namespace hil::client::test
