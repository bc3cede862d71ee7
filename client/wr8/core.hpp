#pragma once
// The WR8 reference client's logic, sans-I/O: login, live DATA state with a
// stale flag, tasks and settings matched by COI with answer and completion
// timeouts, and reconnect with backoff (docs/clients/wr8.md).

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "client/common/comm_log.hpp"
#include "client/common/connection.hpp"
#include "client/common/connection_core.hpp"
#include "link/time.hpp"
#include "protocol/common/bytes.hpp"
#include "protocol/wr8/codec.hpp"
#include "protocol/wr8/message.hpp"

namespace hil::client::wr8 {

using link::Duration;
using link::Time;
namespace proto = protocol::wr8;

struct ClientConfig {
  /// Byte-level choices; `profile.auth_text` is what AUTH carries.
  proto::Profile profile;
  /// Without AUTH-REPLY this long after the connection opened, the
  /// connection counts as failed: it is closed and retried.
  Duration auth_timeout = link::seconds(2);
  /// Without DATA this long (5 periods of the vehicle's 100 ms) the live
  /// state is flagged stale.
  Duration stale_after = link::milliseconds(500);
  /// The first RESPONSE (or SETTINGS) must come this long after the send.
  Duration answer_timeout = link::milliseconds(500);
  /// After `started`, `completed` or `error` must come this long after it,
  /// per task code (check, drive, turn, blink, get-settings).
  std::array<Duration, proto::kTaskCount> completion_timeout = {
      link::seconds(1), link::seconds(30), link::seconds(3), link::seconds(5), link::seconds(1)};
  /// Delays before reconnect attempt 1, 2, 3...; the last repeats forever.
  std::vector<Duration> reconnect_delays = {link::seconds(1), link::seconds(2), link::seconds(4),
                                            link::seconds(8)};
};

/// The states of the shared vocabulary the WR8 cores reach: disconnected,
/// connecting, authenticating (AUTH sent, waiting for AUTH-REPLY),
/// connected (logged in: DATA flows, requests may be sent), reconnecting.
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
  protocol::Bytes bytes;  ///< one complete packet
  friend bool operator==(const SendBytes&, const SendBytes&) = default;
};
using Action = std::variant<OpenConnection, SendBytes, CloseConnection>;

/// The vehicle as the last DATA showed it.
struct LiveState {
  proto::State state = proto::State::wait;
  std::uint32_t timestamp_ms = 0;
  std::optional<double> odometry_cm;
  std::optional<double> speed_mps;
  std::optional<double> wheel_angle_deg;
  std::optional<double> battery_percent;
  Time received{0};  ///< when the client got it
};

// ---- events for a UI (and ConnectionEvent) ----
/// Logged in: what AUTH-REPLY said.
struct LoginEvent {
  proto::AuthReply reply;
};
/// Why a connection failed before login.
struct LoginFailedEvent {
  std::string reason;  ///< "AUTH-REPLY timeout", "closed before AUTH-REPLY", "connect failed"
};
struct TelemetryEvent {
  LiveState live;
};
/// Which DATA stream a stale flag is about: the document's and v2019's one
/// DATA packet, or one of the two rates of the head programs.
enum class DataStream : std::uint8_t { data, high_freq, low_freq };
std::string_view to_string(DataStream s);  ///< "DATA", "HIGH-FREQ DATA", "LOW-FREQ DATA"

struct StaleEvent {
  bool stale = false;  ///< true: raised, false: cleared by fresh DATA
  DataStream stream = DataStream::data;
};

enum class RequestKind : std::uint8_t { task, settings };
enum class RequestState : std::uint8_t {
  sent,
  started,    ///< RESPONSE started
  completed,  ///< RESPONSE completed
  error,      ///< RESPONSE error
  timed_out,  ///< no answer in time; the COI is free again and a late answer is ignored
  cancelled,  ///< the connection ended first
};
std::string_view to_string(RequestState s);

struct RequestEvent {
  std::uint8_t coi = 0;
  RequestKind kind = RequestKind::task;
  proto::TaskCode task = proto::TaskCode::check;  ///< with kind task
  RequestState state = RequestState::sent;
  /// What a person should know beyond the state, or empty: for a dialect
  /// whose vehicle answers some requests never or drops them silently, why
  /// no answer will come or what a timeout most likely means.
  std::string note = {};
};
/// The settings a get-settings task returned.
struct SettingsEvent {
  std::uint8_t coi = 0;
  std::vector<proto::Setting> settings;
};
/// A RESPONSE or SETTINGS whose COI matches no open request (late or unknown).
struct IgnoredEvent {
  proto::Message message;
};
using client::ParseErrorEvent;
using Event = std::variant<ConnectionEvent, LoginEvent, LoginFailedEvent, TelemetryEvent,
                           StaleEvent, RequestEvent, SettingsEvent, IgnoredEvent, ParseErrorEvent>;

enum class Refusal : std::uint8_t {
  none,
  not_connected,  ///< nothing is sent before login
  bad_request,    ///< the profile cannot encode it (parameter count, block too long)
  busy,           ///< all 256 COIs are waiting for answers
};
std::string_view to_string(Refusal r);

struct SubmitResult {
  std::uint8_t coi = 0;
  Refusal refusal = Refusal::none;
  explicit operator bool() const { return refusal == Refusal::none; }
};

/// What both WR8 cores (the document's dialect here, the real programs'
/// in svgui_core.hpp) share beyond the connection: the login once the
/// connection opens (AUTH, then AUTH-REPLY within a time limit) and a
/// failed login, reported and retried after the backoff delay.
template <class Event>
class LoginCore : public ConnectionCore<Action, Event> {
  using Base = ConnectionCore<Action, Event>;

 public:
  /// The connection could not be opened: a failed login.
  void on_connect_failed(Time now) {
    if (this->state() != ConnectionState::connecting) return;
    login_failed(now, "connect failed");
  }

 protected:
  using Base::Base;

  /// AUTH goes out: authenticating, and a failed login unless the login
  /// ends within `timeout`.
  void await_login(Time now, Duration timeout) {
    this->change_state(ConnectionState::authenticating, this->connection_.reconnect().attempt());
    login_deadline_ = now + timeout;
  }
  /// Logged in: no time limit, and the reconnect count is back to 0.
  void login_done() {
    login_deadline_.reset();
    this->connection_.reconnect().succeeded();
  }
  /// No login is awaited any more (the operator disconnected).
  void drop_login_deadline() { login_deadline_.reset(); }
  /// The connection failed before the login: noted, reported, retried.
  void login_failed(Time now, std::string reason) {
    this->note(now, "connection failed: " + reason);
    this->emit(LoginFailedEvent{std::move(reason)});
    login_deadline_.reset();
    this->retry_later(now);
  }
  /// When the login's time limit has passed at `now`: closed and failed.
  void check_login_deadline(Time now) {
    const auto deadline = login_deadline();
    if (!deadline || now < *deadline) return;
    this->actions_.push_back(CloseConnection{});
    login_failed(now, "AUTH-REPLY timeout");
  }
  /// Bytes from the vehicle once AUTH went out: `decoder` turns
  /// them into `items`; each packet is logged (its hex and `describe(m)`)
  /// and handed to `handle(now, m)`, each parse error logged and reported.
  /// A packet after which the connection is no longer up ends the rest.
  template <class Decoder, class Item, class Describe, class Handle>
  void receive(Time now, protocol::ByteView bytes, Decoder& decoder, std::vector<Item>& items,
               Describe describe, Handle handle) {
    const auto open = [this] {
      return this->state() == ConnectionState::authenticating ||
             this->state() == ConnectionState::connected;
    };
    if (!open()) return;
    items.clear();
    decoder.feed(bytes, items);
    for (const auto& item : items) {
      if (const auto* err = std::get_if<protocol::DecodeError>(&item)) {
        this->parse_error(now, protocol::to_hex(err->raw), *err);
        continue;
      }
      const auto& frame = std::get<0>(item);  // a Frame: not a DecodeError
      this->log_->add({now, LogKind::rx, protocol::to_hex(frame.raw), describe(frame.message)});
      handle(now, frame.message);
      if (!open()) break;
    }
  }
  /// The end of the login's time limit while authenticating.
  std::optional<Time> login_deadline() const {
    if (this->state() != ConnectionState::authenticating) return std::nullopt;
    return login_deadline_;
  }
  /// What the connection itself waits for, the earliest first: a reconnect
  /// attempt, the login's time limit.
  link::Earliest connection_wakeup() const {
    link::Earliest next;
    next.consider(this->connection_.reconnect().due());
    next.consider(login_deadline());
    return next;
  }

 private:
  std::optional<Time> login_deadline_;
};

class Wr8ClientCore : public LoginCore<Event> {
 public:
  explicit Wr8ClientCore(ClientConfig config = {},
                         std::shared_ptr<CommLog> log = std::make_shared<CommLog>());

  // ---- operator ----
  /// Connects (at once, also while waiting to reconnect); reconnects from then on.
  void connect(Time now);
  /// Closes and stays disconnected; open requests are cancelled.
  void disconnect(Time now);
  SubmitResult task(Time now, proto::TaskCode code, std::vector<proto::Word> params = {});
  SubmitResult drive(Time now, std::int32_t distance_cm);
  SubmitResult turn(Time now, std::int32_t angle_deg);
  SubmitResult get_settings(Time now);
  SubmitResult set_settings(Time now, std::vector<proto::Setting> settings);

  // ---- driver (and on_connect_failed) ----
  void on_connected(Time now);
  void on_bytes(Time now, protocol::ByteView bytes);
  /// The connection ended without the core asking (peer close, reset).
  void on_closed(Time now);
  /// Runs what is due (timeouts, reconnect, stale check).
  void on_timer(Time now);
  std::optional<Time> next_wakeup() const;

  // ---- state (and state(), log(), take_actions(), take_events()) ----
  const std::optional<LiveState>& live() const { return live_; }
  bool stale() const { return stale_; }
  /// Settings from the last get-settings answer.
  const std::vector<proto::Setting>& settings() const { return settings_; }
  std::size_t open_requests() const;
  const ClientConfig& config() const { return config_; }

 protected:
  // ---- the document dialect's rules, one function each (docs/clients/wr8.md) ----
  // The property tests (tests/property/) override them to show that a
  // client that breaks one is caught; the client itself never does. The
  // reconnect rule, reconnect_time(), is ConnectionCore's.

  /// Whether the login waits for the vehicle's AUTH-REPLY before the client
  /// counts itself logged in and sends requests: always ("Login").
  virtual bool login_awaits_reply() const { return true; }
  /// Which open request the RESPONSE `r` answers: the one whose COI it
  /// carries ("Requests and COI").
  virtual std::uint8_t answered_coi(const proto::Response& r) const { return r.coi; }

  /// The COI of the request sent last of those still open, if any.
  std::optional<std::uint8_t> newest_open_coi() const;

 private:
  struct Pending {
    RequestKind kind = RequestKind::task;
    proto::TaskCode task = proto::TaskCode::check;
    bool started = false;
    Time deadline{0};
    std::uint64_t order = 0;  // requests sent before it on this core
  };

  SubmitResult send_request(Time now, RequestKind kind, proto::TaskCode task,
                            const proto::Message& message);
  void send(Time now, const proto::Message& message);
  void handle(Time now, const proto::Message& message);
  void logged_in(const proto::AuthReply& reply);
  void on_response(Time now, const proto::Response& r);
  void finish(std::uint8_t coi, RequestState state);
  void ignored(Time now, const proto::Message& message);
  void lost(Time now, std::string_view why);
  void cancel_all();
  double value_of(const proto::DataValue& v) const;

  // connection_'s reconnect count goes back to 0 at login.
  ClientConfig config_;
  proto::Decoder decoder_;
  std::vector<proto::Item> items_;

  std::uint8_t next_coi_ = 0;
  std::uint64_t requests_sent_ = 0;
  std::array<std::optional<Pending>, 256> pending_{};

  std::optional<LiveState> live_;
  std::optional<Time> last_data_;  // on this connection: a new login waits for its own DATA
  bool stale_ = false;
  std::vector<proto::Setting> settings_;
};

}  // namespace hil::client::wr8
