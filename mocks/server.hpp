#pragma once
// Binds a mock firmware to a listener: each client that connects is joined
// to the firmware through a Link (faults, wire capture), and the firmware's
// wakeups are scheduled on the executor, so the same server runs the car
// under the virtual-time driver (mem://) and the real-time driver (tcp://,
// pty://). One client at a time; see docs/mocks.md for what a second gets.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "link/endpoint.hpp"
#include "link/faults/profile.hpp"
#include "link/link.hpp"
#include "link/transport.hpp"
#include "mocks/firmware.hpp"

namespace hil::mocks {

struct ServerOptions {
  link::Endpoint listen;  ///< tcp://, pty:// or mem://
  /// Frame-aware faults and decoded captures; null: the firmware's adapter().
  std::shared_ptr<const link::ProtocolAdapter> protocol;
  link::FaultProfile faults;  ///< rules for both directions of every client's link
  std::uint64_t seed = 0;     ///< client N's link uses seed + N - 1
  /// NDJSON wire log (records carry "link": "<name>/link<N>"); empty: none.
  std::string wire_log_path;
  std::string name = "car";  ///< for logs and wire-log link ids
  /// Extra observers on every client's link (tests, the live view).
  std::vector<std::shared_ptr<link::LinkObserver>> observers;
  /// One line per event for a person (connections, faults); may be empty.
  std::function<void(const std::string&)> log;
};

class MockServer {
 public:
  /// `context` and `firmware` must outlive the server.
  MockServer(link::TransportContext& context, Firmware& firmware, ServerOptions options);
  ~MockServer();
  MockServer(const MockServer&) = delete;
  MockServer& operator=(const MockServer&) = delete;

  /// Listens and starts the firmware's clock (the car runs with no client
  /// too). Throws as link::listen() does.
  void start();
  /// Stops listening, closes the client's connection, stops the clock.
  void close();
  /// Replaces the fault rules: on the current client's link at once (each
  /// direction keeps its random stream and frame counts) and on every later
  /// one; an empty profile turns faults off.
  void set_faults(link::FaultProfile faults);
  /// Where a client connects (the listener's URI, real port or pty path).
  std::string address() const;

  bool client_connected() const;
  std::uint64_t clients_served() const { return served_; }
  /// Connections turned away because a client was already connected, or
  /// by a fault rule's refuse.
  std::uint64_t turned_away() const { return turned_away_; }
  /// Faults injected on every link so far (refused connections included).
  std::uint64_t faults_injected() const;
  /// The same, of one kind.
  std::uint64_t faults_injected(link::FaultKind kind) const;

  Firmware& firmware() { return firmware_; }

 private:
  void on_accept(link::BytePipePtr client);
  void flush();
  void reschedule();
  void say(const std::string& line) const;
  class FaultTally;

  link::TransportContext& context_;
  Firmware& firmware_;
  ServerOptions options_;
  std::unique_ptr<link::Listener> listener_;
  std::unique_ptr<link::FaultInjector> gate_;  // answers refuse_connection()
  std::shared_ptr<link::Link> link_;
  link::BytePipePtr firmware_end_;  // the firmware's side of the mem pipe into the link
  link::WakeupTimer timer_;         // the firmware's next wakeup
  std::uint64_t served_ = 0;
  std::uint64_t accepted_ = 0;
  std::uint64_t turned_away_ = 0;
  std::shared_ptr<FaultTally> tally_;  // on every link, and told of the gate's refusals
  bool running_ = false;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::mocks
