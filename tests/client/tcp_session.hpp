#pragma once
// A client session (LogiSession, Wr8Session) against a mock car over real
// TCP (tcp://127.0.0.1:0) under the real-time driver; waits are bounded.

#include <functional>
#include <utility>
#include <vector>

#include "client/common/connection.hpp"
#include "link/endpoint.hpp"
#include "link/time.hpp"
#include "sim/world.hpp"
#include "tests/link/transports/real_time.hpp"
#include "tests/mocks/real_time_car.hpp"

namespace hil::client::test {

template <class Session, class Firmware, class Event>
struct SessionOverTcp {
  explicit SessionOverTcp(sim::VehicleDef vehicle)
      : car(std::move(vehicle), mocks::test::listening_on("tcp://127.0.0.1:0")),
        session(car.context, link::parse_endpoint(car.server.address()), {},
                [this](link::Time, const Event& e) { events.push_back(e); }) {}

  /// Connects and waits until the session is connected; whether it is.
  bool connect() {
    session.connect();
    return run_until([&] { return session.core().state() == ConnectionState::connected; });
  }

  /// Runs the car's io_context until `done()` holds (10 s at most); whether it did.
  bool run_until(const std::function<bool()>& done) { return link::test::run_until(car.io, done); }

  mocks::test::RealTimeCar<Firmware> car;
  std::vector<Event> events;  ///< every event the session reported, in order
  Session session;
};

}  // namespace hil::client::test
