#pragma once
// What the cores of the TCP clients (LOGI, and WR8 in the document's and
// the real programs' dialects) share: a connection the operator wants kept
// up, a communication log, and the actions and events handed to the driver.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "client/common/comm_log.hpp"
#include "client/common/connection.hpp"
#include "link/time.hpp"
#include "protocol/common/decode.hpp"

namespace hil::client {

// ---- actions for the driver, beside the family's SendBytes ----
/// Open the connection; the driver answers on_connected or on_connect_failed.
struct OpenConnection {
  friend bool operator==(const OpenConnection&, const OpenConnection&) = default;
};
/// Close the connection; what it still reports is not news.
struct CloseConnection {
  friend bool operator==(const CloseConnection&, const CloseConnection&) = default;
};

/// Received bytes that were not a valid frame (dropped).
struct ParseErrorEvent {
  protocol::DecodeError error;
};

/// The base of a sans-I/O core: `Action` a variant holding OpenConnection
/// and CloseConnection, `Event` a variant holding ConnectionEvent and
/// ParseErrorEvent.
template <class Action, class Event>
class ConnectionCore {
 public:
  std::vector<Action> take_actions() { return std::exchange(actions_, {}); }
  std::vector<Event> take_events() { return std::exchange(events_, {}); }

  virtual ~ConnectionCore() = default;
  ConnectionCore(const ConnectionCore&) = default;
  ConnectionCore(ConnectionCore&&) = default;
  ConnectionCore& operator=(const ConnectionCore&) = default;
  ConnectionCore& operator=(ConnectionCore&&) = default;

  ConnectionState state() const { return connection_.state(); }
  const std::shared_ptr<CommLog>& log() const { return log_; }

 protected:
  /// A null `log` gets a log of its own.
  ConnectionCore(std::shared_ptr<CommLog> log, Backoff backoff)
      : log_(log ? std::move(log) : std::make_shared<CommLog>()), connection_(std::move(backoff)) {}

  void emit(Event e) { events_.push_back(std::move(e)); }
  void note(link::Time now, std::string text) {
    log_->add({now, LogKind::note, {}, std::move(text)});
  }
  /// Bytes that were not a valid frame: logged (`raw` as the log shows
  /// them, with the error's kind and detail) and reported.
  void parse_error(link::Time now, std::string raw, const protocol::DecodeError& error) {
    std::string description(protocol::to_string(error.kind));
    if (!error.detail.empty()) description += ": " + error.detail;
    log_->add({now, LogKind::parse_error, std::move(raw), std::move(description)});
    emit(ParseErrorEvent{error});
  }
  /// Moves to `s` and reports it; false when `s` is the state already.
  bool change_state(ConnectionState s, int attempt = 0) {
    const auto changed = connection_.set(s, attempt);
    if (changed) emit(*changed);
    return changed.has_value();
  }
  /// The operator's connect: the connection is wanted from now on and, when
  /// none is open or opening, opened now (reported with `attempt`): true then.
  bool open_wanted(link::Time now, int attempt) {
    if (!connection_.want()) return false;
    note(now, "connect");
    change_state(ConnectionState::connecting, attempt);
    actions_.push_back(OpenConnection{});
    return true;
  }
  /// The operator's disconnect: nothing is retried and an open connection
  /// is closed.
  void close_unwanted() {
    if (connection_.unwant()) actions_.push_back(CloseConnection{});
  }
  /// The backoff rule: the reconnect attempt due `delay` after a failure
  /// or loss at `now` goes out `delay` later. The one place every family's
  /// client applies it; the property tests override it to plant a client
  /// that does not wait (tests/property/*planted_bug.hpp).
  virtual link::Time reconnect_time(link::Time now, link::Duration delay) const {
    return now + delay;
  }
  /// A failed or lost connection: retried at reconnect_time() while wanted
  /// (reconnecting), else disconnected.
  void retry_later(link::Time now) {
    const link::Time at = reconnect_time(now, connection_.reconnect().next_delay());
    if (const auto changed = connection_.retry_at(at)) emit(*changed);
  }
  /// Opens the connection again when a scheduled attempt is due: true then.
  bool reconnect_if_due(link::Time now) {
    const auto attempt = connection_.take_due_attempt(now);
    if (!attempt) return false;
    note(now, "reconnect attempt " + std::to_string(*attempt));
    change_state(ConnectionState::connecting, *attempt);
    actions_.push_back(OpenConnection{});
    return true;
  }

  std::shared_ptr<CommLog> log_;
  ConnectionLifecycle connection_;
  std::vector<Action> actions_;
  std::vector<Event> events_;
};

}  // namespace hil::client
