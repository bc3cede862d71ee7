#pragma once
// The LOGI reference client's logic, sans-I/O: connection lifecycle with
// reconnect, frame decoding, the one-in-flight command dispatcher with
// feedback timeouts and retries, and the safety guard (docs/clients/logi.md).

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "client/common/comm_log.hpp"
#include "client/common/connection.hpp"
#include "client/common/connection_core.hpp"
#include "link/time.hpp"
#include "protocol/common/bytes.hpp"
#include "protocol/logi/codec.hpp"
#include "protocol/logi/message.hpp"

namespace hil::client::logi {

using link::Duration;
using link::Time;
namespace proto = protocol::logi;

/// Local id of one operator request; 0 is never used (unsolicited feedback).
using RequestId = std::uint64_t;

struct ClientConfig {
  Duration feedback_timeout = link::milliseconds(800);
  /// Resends after a timeout for SP, MD and MV:STOP (3 sends in all).
  int max_retries = 2;
  /// Delays before reconnect attempt 1, 2, 3...; the last repeats forever.
  std::vector<Duration> reconnect_delays = {link::seconds(1), link::seconds(2), link::seconds(3)};
  /// Without a STAT for this long the stale warning is raised.
  Duration stale_after = link::seconds(2);
  /// Repeat the held direction's MV while it is held (off: edge-triggered).
  bool keepalive = false;
  Duration keepalive_period = link::milliseconds(300);
  proto::DecoderOptions decoder;
};

/// The states of the shared vocabulary the LOGI core reaches:
/// disconnected, connecting, connected, reconnecting.
using client::ConnectionEvent;
using client::ConnectionState;
using client::to_string;

/// The log: one entry per frame sent or received, per parse error and per note.
using client::CommLog;
using client::LogEntry;
using client::LogKind;

// ---- actions for the driver ----
using client::CloseConnection;
using client::OpenConnection;
struct SendBytes {
  std::string text;  ///< one complete frame
  friend bool operator==(const SendBytes&, const SendBytes&) = default;
};
using Action = std::variant<OpenConnection, SendBytes, CloseConnection>;

// ---- events for a UI (and ConnectionEvent) ----
/// A decoded STAT.
struct StatusEvent {
  proto::Status status;
};
/// A decoded FB; `request` is 0 when no command in flight matched it.
struct FeedbackEvent {
  RequestId request = 0;
  proto::Feedback feedback;
};
enum class CommandState : std::uint8_t {
  sent,       ///< written to the car (again, for a retry)
  accepted,   ///< FB:x:1
  rejected,   ///< FB:x:0
  uncertain,  ///< no FB within the timeout and no (further) automatic retry
  cancelled,  ///< dropped unsent or abandoned: connection lost, emergency stop
};
std::string_view to_string(CommandState s);
/// Progress of one request (each send, then its outcome).
struct CommandEvent {
  RequestId request = 0;
  proto::Message command;
  CommandState state = CommandState::sent;
  int attempt = 1;  ///< 1 = first send
  /// With `uncertain`: confirm_resend(request) will send it again.
  bool resend_on_confirm = false;
};
struct StaleEvent {
  bool stale = false;  ///< true: raised, false: cleared by a fresh STAT
};
/// Something the operator should be told ("Not in manual mode, switching to MAN").
struct NoticeEvent {
  std::string text;
};
using client::ParseErrorEvent;
/// Whether movement controls should be enabled, and why not.
struct MovementEvent {
  bool enabled = false;
  std::string reason;
};
using Event = std::variant<ConnectionEvent, StatusEvent, FeedbackEvent, CommandEvent, StaleEvent,
                           NoticeEvent, ParseErrorEvent, MovementEvent>;

/// Why an operator request was not taken.
enum class Refusal : std::uint8_t {
  none,
  not_connected,           ///< nothing is sent while the link is down
  mode_speed_unconfirmed,  ///< movement needs MD and SP from the operator on this connection
  not_held,                ///< release() without a held direction
  unknown_request,         ///< confirm_resend() for a request not awaiting confirmation
  not_a_command,           ///< submit() of a STAT or FB
};
std::string_view to_string(Refusal r);

struct SubmitResult {
  RequestId request = 0;  ///< 0 when refused
  Refusal refusal = Refusal::none;
  explicit operator bool() const { return refusal == Refusal::none; }
};

class LogiClientCore : public ConnectionCore<Action, Event> {
 public:
  /// The client's time resolution: the smallest step between two instants.
  static constexpr Duration kTick{1};

  explicit LogiClientCore(ClientConfig config = {},
                          std::shared_ptr<CommLog> log = std::make_shared<CommLog>());
  virtual ~LogiClientCore() = default;
  LogiClientCore(const LogiClientCore&) = default;
  LogiClientCore(LogiClientCore&&) = default;
  LogiClientCore& operator=(const LogiClientCore&) = default;
  LogiClientCore& operator=(LogiClientCore&&) = default;

  // ---- operator ----
  /// Connects (at once, also while reconnecting); reconnects from then on.
  void connect(Time now);
  /// Closes and stays disconnected (no reconnect).
  void disconnect(Time now);
  /// Queues a command (SP, ST, GS, MD, MV). MV other than STOP and ST:RUN
  /// count as movement.
  SubmitResult submit(Time now, const proto::Message& command);
  /// A direction button went down: MV:<dir>, held until release().
  SubmitResult press(Time now, proto::Direction direction);
  /// The held direction's button came up: MV:STOP.
  SubmitResult release(Time now);
  /// MV:STOP, then ST:STOP unless the car is known to be in MAN, written at
  /// once ahead of the queue; queued movement is cancelled. The ST:STOP is
  /// resent every feedback timeout until the car answers it.
  SubmitResult emergency_stop(Time now);
  /// Resends an uncertain ST:RUN or GS (same request id).
  SubmitResult confirm_resend(Time now, RequestId request);

  // ---- driver ----
  void on_connected(Time now);
  void on_connect_failed(Time now);
  void on_bytes(Time now, protocol::ByteView bytes);
  /// The connection ended without the core asking (peer close, reset).
  void on_closed(Time now);
  /// Runs what is due (timeouts, reconnect, stale check, keepalive).
  void on_timer(Time now);
  std::optional<Time> next_wakeup() const;

  // ---- state (and state(), log(), take_actions(), take_events()) ----
  bool movement_enabled() const;
  bool stale() const { return stale_; }
  std::optional<proto::Direction> held() const { return held_; }
  /// The mode from the last STAT or accepted MD on this connection.
  std::optional<proto::Mode> known_mode() const { return mode_; }
  const std::optional<proto::Status>& last_status() const { return status_; }
  std::size_t queued() const { return queue_.size(); }
  std::size_t in_flight() const { return flight_.size(); }
  const ClientConfig& config() const { return config_; }

 protected:
  // ---- the protocol's rules, one function each (docs/clients/logi.md) ----
  // The property tests (tests/property/) override them to show that a
  // client that breaks one is caught; the client itself never does.

  /// Whether a command without feedback is sent again by itself: SP, MD
  /// and MV:STOP (max_retries times), never ST:RUN.
  virtual bool retryable(const proto::Message& m) const;
  // When a reconnect attempt goes out: reconnect_time(), ConnectionCore's.
  /// How long without a STAT raises the stale warning: stale_after.
  virtual Duration stale_after() const { return config_.stale_after; }
  /// When the stale warning rises after the STAT (or connect) at
  /// `last_stat`: the documentation asks for "more than" stale_after, so
  /// the first instant after it, one tick (1 ns, the client's time
  /// resolution) on. Exactly stale_after later it is not raised yet.
  virtual Time stale_at(Time last_stat) const { return last_stat + stale_after() + kTick; }
  /// Whether a frame from the car counts as fresh telemetry (it restarts the
  /// stale clock and clears the warning): a STAT only, never an FB.
  virtual bool refreshes_status(const proto::Message& m) const {
    return std::holds_alternative<proto::Status>(m);
  }
  /// Whether release() writes MV:STOP: always.
  virtual bool stop_on_release() const { return true; }
  /// What an emergency stop writes, in this order: MV:STOP, then ST:STOP
  /// unless the car is known to be in MAN.
  virtual std::vector<proto::Message> emergency_stop_commands() const;
  /// Whether an emergency stop's `m` is written again every feedback
  /// timeout until the car answers it, the link goes or a newer emergency
  /// stop replaces it: ST:STOP. Stopping a stopped car changes nothing, so a
  /// repeat is safe, and in AUTO it is the only stop the car obeys.
  virtual bool resend_until_answered(const proto::Message& m) const;
  /// Whether a command that got no feedback is followed by MV:STOP, written
  /// ahead of the queue: every MV other than STOP (the documentation's
  /// fail-safe for movement commands; the move itself is not resent).
  virtual bool stop_after_timeout(const proto::Message& m) const;
  /// Decodes one read's bytes into `items`, after what the earlier reads of
  /// the connection left (a frame may span reads).
  virtual void decode(protocol::ByteView bytes, std::vector<proto::Item>& items);

 private:
  enum class Origin : std::uint8_t { operator_request, internal };
  struct Pending {
    RequestId id = 0;
    proto::Message command;
    int attempt = 0;                // sends so far
    bool mode_switch_done = false;  // FB:MV:0 has already led to MD:MAN once
    bool switch_mode_on_reject = true;
    bool until_answered = false;  // an emergency stop's ST:STOP: resent without limit
    Time deadline{0};
  };

  RequestId enqueue(Time now, proto::Message command, bool front = false,
                    bool switch_mode_on_reject = true);
  void pump(Time now);
  void send(Time now, Pending p);
  void on_frame(Time now, const protocol::Frame<proto::Message>& frame);
  void on_feedback(Time now, const proto::Feedback& fb);
  void on_timeout(Time now, Pending p);
  void lost(Time now, std::string_view why);
  /// A failed or lost connection: the next attempt is scheduled (at
  /// reconnect_time) while the operator wants it, else disconnected.
  void reconnect_or_stop(Time now);
  void set_state(ConnectionState s, int attempt = 0);
  void update_movement();
  static bool is_movement(const proto::Message& m);
  static bool resend_on_confirm(const proto::Message& m);

  // connection_'s reconnect count goes back to 0 once the car sends a valid frame.
  ClientConfig config_;
  proto::Decoder decoder_;
  std::vector<proto::Item> items_;

  RequestId next_id_ = 1;
  std::deque<Pending> queue_;
  std::deque<Pending> flight_;  // normally one; an emergency stop adds its frames
  std::vector<Pending> awaiting_confirm_;

  std::optional<proto::Direction> held_;
  std::optional<Time> keepalive_at_;
  bool mode_confirmed_ = false;
  bool speed_confirmed_ = false;
  std::optional<proto::Mode> mode_;
  std::optional<proto::Status> status_;
  std::optional<Time> last_stat_;
  bool stale_ = false;
  bool movement_reported_ = false;
  bool movement_reported_value_ = false;
};

}  // namespace hil::client::logi
