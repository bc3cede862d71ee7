#pragma once
// A mock car under the real-time driver: an io_context and its executor, a
// world with one vehicle, the vehicle's firmware and a MockServer on a real
// endpoint (tcp://, or pty:// in a temporary directory), listening from
// construction on.

#include <functional>
#include <memory>
#include <string>
#include <system_error>
#include <utility>

#include <asio/io_context.hpp>

#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"
#include "mocks/server.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/link/transports/real_time.hpp"
#include "tests/mocks/mock_test_support.hpp"
#include "tests/mocks/serial_support.hpp"

namespace hil::mocks::test {

/// Server options listening on `uri` (tcp://..., pty://...) under `name`.
inline ServerOptions listening_on(const std::string& uri, std::string name = "car") {
  ServerOptions options;
  options.listen = link::parse_endpoint(uri);
  options.name = std::move(name);
  return options;
}

template <class FirmwareT>
struct RealTimeCar {
  /// Puts `vehicle_def` in a world of its own, runs `FirmwareT(world,
  /// vehicle, firmware_args...)` behind a server with `options`, and starts it.
  template <class... FirmwareArgs>
  RealTimeCar(sim::VehicleDef vehicle_def, ServerOptions options, FirmwareArgs&&... firmware_args)
      : vehicle(world.add_vehicle(std::move(vehicle_def))),
        firmware(world, vehicle, std::forward<FirmwareArgs>(firmware_args)...),
        server(context, firmware, std::move(options)) {
    server.start();
  }

  asio::io_context io;
  link::AsioExecutor executor{io};
  link::TransportContext context{executor, &io};
  sim::World world{sim::WorldDef{}};
  sim::Vehicle& vehicle;
  FirmwareT firmware;
  MockServer server;
};

/// Connects a client to `car` at its address and runs the io_context (10 s
/// at most) until the firmware has it or the connection is refused: the pipe
/// goes to `pipe`, started with `handlers`, and a refusal to `refused` (when
/// given). Whether the firmware has the client.
template <class FirmwareT>
bool connect_and_wait(RealTimeCar<FirmwareT>& car, link::BytePipePtr& pipe,
                      link::BytePipe::Handlers handlers,
                      std::function<void(std::error_code)> refused = {}) {
  auto was_refused = std::make_shared<bool>(false);
  connect_client(car.context, car.server, pipe, std::move(handlers),
                 [was_refused, refused = std::move(refused)](std::error_code ec) {
                   *was_refused = true;
                   if (refused) refused(ec);
                 });
  link::test::run_until(car.io, [&] { return *was_refused || (pipe && car.firmware.connected()); });
  return pipe && car.firmware.connected();
}

/// pty://<a fresh temporary directory>/<port><query>, removed at the end.
struct PtyUri {
  PtyUri(const std::string& port, const std::string& query)
      : dir("hil-" + port), uri("pty://" + (dir.path / port).string() + query) {}
  TempDir dir;
  std::string uri;
};

/// A mock car listening on a PtyUri.
template <class FirmwareT>
struct PtyCar : PtyUri, RealTimeCar<FirmwareT> {
  template <class... FirmwareArgs>
  PtyCar(const std::string& port, const std::string& query, sim::VehicleDef vehicle_def,
         FirmwareArgs&&... firmware_args)
      : PtyUri(port, query),
        RealTimeCar<FirmwareT>(std::move(vehicle_def), listening_on(uri),
                               std::forward<FirmwareArgs>(firmware_args)...) {}
};

}  // namespace hil::mocks::test
