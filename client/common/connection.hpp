#pragma once
// How a reference client's connection stands, in one vocabulary for every
// car, and the reconnect schedule the clients share: the delays between
// attempts and the lifecycle of a connection the operator wants kept up.

#include <cstdint>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "base/enum_names.hpp"
#include "link/time.hpp"

namespace hil::client {

/// Every family's core reports these; each reaches only some of them. LOGI:
/// disconnected, connecting, connected, reconnecting; WR8 also
/// authenticating (AUTH sent, waiting for AUTH-REPLY); the Arduino link
/// disconnected (closed), connecting (the port is opening), connected
/// (open), degraded, reconnecting and down.
enum class ConnectionState : std::uint8_t {
  disconnected,
  connecting,      ///< the transport is being opened
  authenticating,  ///< open, logging in
  connected,       ///< requests may be sent
  degraded,        ///< the link stopped answering; a reconnect is due
  reconnecting,    ///< waiting for or making a reconnect attempt
  down,            ///< given up: only the operator opens it again
};
/// "disconnected", "connecting", "authenticating", "connected", "degraded",
/// "reconnecting", "down": the words a run's timeline records.
std::string_view to_string(ConnectionState s);
/// The same words, for reading a state back and listing the states.
extern const base::EnumNames<ConnectionState, 7> kConnectionStateNames;

/// The connection changed state (LOGI and WR8 report it as an event).
struct ConnectionEvent {
  ConnectionState state = ConnectionState::disconnected;
  int attempt = 0;  ///< reconnect attempt number (0: operator's connect)
  friend bool operator==(const ConnectionEvent&, const ConnectionEvent&) = default;
};

/// The delays between reconnect attempts.
class Backoff {
 public:
  /// `delays[0]` before attempt 1, `delays[1]` before attempt 2, ...; the
  /// last repeats forever. `delays` must not be empty.
  static Backoff ladder(std::vector<link::Duration> delays);
  /// `first` before attempt 1, twice as long before each further one.
  static Backoff doubling(link::Duration first);

  /// The delay before attempt `attempt` (1-based).
  link::Duration delay(int attempt) const;

 private:
  Backoff() = default;
  std::vector<link::Duration> ladder_;  // empty: doubling from first_
  link::Duration first_{0};
};

/// One connection's reconnect attempts: how many were scheduled since the
/// connection last proved itself, and when the next one is due.
class ReconnectSchedule {
 public:
  explicit ReconnectSchedule(Backoff backoff) : backoff_(std::move(backoff)) {}

  /// Counts one more attempt and schedules it its backoff delay after
  /// `now`; returns that delay.
  link::Duration schedule(link::Time now);
  /// Counts one more attempt and schedules it at `at`.
  void schedule_at(link::Time at);
  /// The delay the next schedule() would wait.
  link::Duration next_delay() const { return backoff_.delay(attempt_ + 1); }
  /// True (once) when the scheduled attempt is due at `now`; it is then no
  /// longer scheduled.
  bool take_due(link::Time now);
  std::optional<link::Time> due() const { return due_; }
  /// Attempts counted since the last reset().
  int attempt() const { return attempt_; }
  /// Nothing scheduled; the count stays.
  void cancel() { due_.reset(); }
  /// Nothing scheduled and the count back to 0.
  void reset() {
    due_.reset();
    attempt_ = 0;
  }
  /// The connection proved itself: the count is back to 0.
  void succeeded() { attempt_ = 0; }

 private:
  Backoff backoff_;
  int attempt_ = 0;
  std::optional<link::Time> due_;
};

/// The lifecycle of a connection the operator wants kept up (LOGI, WR8):
/// connect() opens it, a failed or lost connection waits its backoff delay
/// (reconnecting) and is opened again while it is wanted, disconnect()
/// closes it for good. A core emits the ConnectionEvent each change returns.
class ConnectionLifecycle {
 public:
  explicit ConnectionLifecycle(Backoff backoff) : reconnect_(std::move(backoff)) {}

  ConnectionState state() const { return state_; }
  /// The operator asked for the connection (connect() since the last disconnect()).
  bool wanted() const { return wanted_; }
  /// connecting, authenticating or connected: a connection is open or opening.
  bool active() const;
  const ReconnectSchedule& reconnect() const { return reconnect_; }
  ReconnectSchedule& reconnect() { return reconnect_; }

  /// Moves to `s`; the event to report, or nothing when `s` is the state already.
  std::optional<ConnectionEvent> set(ConnectionState s, int attempt = 0);
  /// The operator wants the connection: true when it is to be opened now
  /// (it was not active; a scheduled attempt is dropped).
  bool want();
  /// The operator no longer wants it: nothing is scheduled and the attempt
  /// count is back to 0; true when a connection was active (close it).
  bool unwant();
  /// A connection failed or ended: when wanted, the next attempt is
  /// scheduled at `at` (its backoff delay after the failure:
  /// reconnect().next_delay()) and the state is reconnecting; else
  /// disconnected.
  std::optional<ConnectionEvent> retry_at(link::Time at);
  /// The number of the attempt due at `now`, if one is (it is then no
  /// longer scheduled): the caller opens the connection.
  std::optional<int> take_due_attempt(link::Time now);

 private:
  ConnectionState state_ = ConnectionState::disconnected;
  bool wanted_ = false;
  ReconnectSchedule reconnect_;
};

}  // namespace hil::client
