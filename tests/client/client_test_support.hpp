#pragma once
// The virtual-time bench the client core, session and operator tests share:
// the driver, a world with one mock car, its firmware and the mock server on
// a mem:// endpoint, a session to it that keeps every event, running the
// executor until something happened, and picking the events and actions of
// one kind out of what a client produced.

#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "link/endpoint.hpp"
#include "link/executor.hpp"
#include "link/time.hpp"
#include "link/transport.hpp"
#include "mocks/behaviour.hpp"
#include "mocks/server.hpp"
#include "protocol/common/bytes.hpp"
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

/// Connects `core` (a client core) at 0 ms with the connection up at once,
/// and forgets the actions and events that caused.
template <class Core>
void connected_at_zero(Core& core) {
  core.connect(link::Time{0});
  core.on_connected(link::Time{0});
  core.take_actions();
  core.take_events();
}

/// The values of alternative `X` among `all` (variants), in order.
template <class X, class Variant>
std::vector<X> events_of(const std::vector<Variant>& all) {
  std::vector<X> out;
  for (const auto& v : all) {
    if (const auto* x = std::get_if<X>(&v)) out.push_back(*x);
  }
  return out;
}

/// (time, value) of each (time, variant) in `all` that holds an `X`, in order.
template <class X, class Variant>
std::vector<std::pair<link::Time, X>> timed_events_of(
    const std::vector<std::pair<link::Time, Variant>>& all) {
  std::vector<std::pair<link::Time, X>> out;
  for (const auto& [t, v] : all) {
    if (const auto* x = std::get_if<X>(&v)) out.emplace_back(t, *x);
  }
  return out;
}

/// (time, stale flag) of each stale event in `events`.
template <class StaleEvent>
std::vector<std::pair<link::Time, bool>> stale_flags(
    const std::vector<std::pair<link::Time, StaleEvent>>& events) {
  std::vector<std::pair<link::Time, bool>> out;
  for (const auto& [t, e] : events)
    out.emplace_back(t, e.stale);
  return out;
}

/// Whether `all` holds a value equal to `wanted`.
template <class T, class Wanted>
bool has(const std::vector<T>& all, const Wanted& wanted) {
  return std::find(all.begin(), all.end(), T(wanted)) != all.end();
}

/// The bytes of every `Send` action among `actions`, in order.
template <class Send, class Action>
std::vector<protocol::Bytes> sent_bytes(const std::vector<Action>& actions) {
  std::vector<protocol::Bytes> out;
  for (const auto& s : events_of<Send>(actions))
    out.push_back(s.bytes);
  return out;
}

/// A mock car on mem://car and a `Session` (LogiSession, Wr8Session) to it,
/// in virtual time. Every event the session reports is kept with its time
/// and handed on to the handler set with forward_events().
template <class Session, class Firmware, class Event>
class SessionOnMem {
 public:
  using EventHandler = std::function<void(link::Time, const Event&)>;

  /// Runs `Firmware(world, vehicle, firmware_args...)` for `vehicle` behind a
  /// server called `name` with `options`, and a session with `config`.
  template <class Config, class... FirmwareArgs>
  SessionOnMem(std::string name, sim::VehicleDef vehicle, mocks::ServerOptions options,
               Config config, FirmwareArgs&&... firmware_args) {
    options.name = std::move(name);
    car_.start_car(std::move(vehicle), on_mem("car", std::move(options)),
                   std::forward<FirmwareArgs>(firmware_args)...);
    session_ = std::make_unique<Session>(car_.context, link::MemEndpoint{"car"}, std::move(config),
                                         [this](link::Time now, const Event& e) {
                                           events_.emplace_back(now, e);
                                           if (forward_) forward_(now, e);
                                         });
  }

  Session& session() { return *session_; }
  const Session& session() const { return *session_; }
  Firmware& firmware() { return *car_.firmware; }
  mocks::MockServer& server() { return *car_.server; }
  link::VirtualExecutor& executor() { return car_.executor; }
  link::Time now() const { return car_.executor.now(); }
  void run_until(link::Time t) { car_.executor.run_until(t); }
  void run_for(link::Duration d) { car_.executor.run_for(d); }

  /// (time, event) of every event of type `E` so far.
  template <class E>
  std::vector<std::pair<link::Time, E>> of() const {
    return timed_events_of<E>(events_);
  }

 protected:
  void forward_events(EventHandler handler) { forward_ = std::move(handler); }

 private:
  VirtualCar<Firmware> car_;
  std::unique_ptr<Session> session_;
  std::vector<std::pair<link::Time, Event>> events_;
  EventHandler forward_;
};

/// A behaviour that makes the car refuse the next command of kind `match`.
inline mocks::Behaviour reject_next(std::string match) {
  return {.name = "", .when = {}, .action = mocks::Reject{.match = std::move(match), .count = 1}};
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
