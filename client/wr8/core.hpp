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

#include "client/wr8/comm_log.hpp"
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

enum class ConnectionState : std::uint8_t {
  disconnected,
  connecting,      ///< the transport is being opened
  authenticating,  ///< AUTH sent, waiting for AUTH-REPLY
  connected,       ///< logged in: DATA flows, requests may be sent
  waiting_to_reconnect
};
std::string_view to_string(ConnectionState s);

// ---- actions for the driver ----
struct OpenConnection {
  friend bool operator==(const OpenConnection&, const OpenConnection&) = default;
};
struct SendBytes {
  protocol::Bytes bytes;  ///< one complete packet
  friend bool operator==(const SendBytes&, const SendBytes&) = default;
};
struct CloseConnection {
  friend bool operator==(const CloseConnection&, const CloseConnection&) = default;
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

// ---- events for a UI ----
struct ConnectionEvent {
  ConnectionState state = ConnectionState::disconnected;
  int attempt = 0;  ///< reconnect attempt number (0: operator's connect)
};
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
struct ParseErrorEvent {
  protocol::DecodeError error;
};
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

class Wr8ClientCore {
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

  // ---- driver ----
  void on_connected(Time now);
  void on_connect_failed(Time now);
  void on_bytes(Time now, protocol::ByteView bytes);
  /// The connection ended without the core asking (peer close, reset).
  void on_closed(Time now);
  /// Runs what is due (timeouts, reconnect, stale check).
  void on_timer(Time now);
  std::optional<Time> next_wakeup() const;

  std::vector<Action> take_actions() { return std::exchange(actions_, {}); }
  std::vector<Event> take_events() { return std::exchange(events_, {}); }

  // ---- state ----
  ConnectionState state() const { return state_; }
  const std::optional<LiveState>& live() const { return live_; }
  bool stale() const { return stale_; }
  /// Settings from the last get-settings answer.
  const std::vector<proto::Setting>& settings() const { return settings_; }
  std::size_t open_requests() const;
  const std::shared_ptr<CommLog>& log() const { return log_; }
  const ClientConfig& config() const { return config_; }

 private:
  struct Pending {
    RequestKind kind = RequestKind::task;
    proto::TaskCode task = proto::TaskCode::check;
    bool started = false;
    Time deadline{0};
  };

  SubmitResult send_request(Time now, RequestKind kind, proto::TaskCode task,
                            const proto::Message& message);
  void send(Time now, const proto::Message& message);
  void handle(Time now, const proto::Message& message);
  void on_response(Time now, const proto::Response& r);
  void finish(std::uint8_t coi, RequestState state);
  void ignored(Time now, const proto::Message& message);
  void login_failed(Time now, std::string reason);
  void lost(Time now, std::string_view why);
  void cancel_all();
  void schedule_reconnect(Time now);
  void set_state(ConnectionState s, int attempt = 0);
  void note(Time now, std::string text);
  void emit(Event e) { events_.push_back(std::move(e)); }
  double value_of(const proto::DataValue& v) const;

  ClientConfig config_;
  std::shared_ptr<CommLog> log_;
  proto::Decoder decoder_;
  std::vector<proto::Item> items_;
  std::vector<Action> actions_;
  std::vector<Event> events_;

  ConnectionState state_ = ConnectionState::disconnected;
  bool want_connected_ = false;
  int reconnect_attempt_ = 0;  // attempts since the last login
  std::optional<Time> reconnect_at_;
  std::optional<Time> auth_deadline_;

  std::uint8_t next_coi_ = 0;
  std::array<std::optional<Pending>, 256> pending_{};

  std::optional<LiveState> live_;
  std::optional<Time> last_data_;  // on this connection: a new login waits for its own DATA
  bool stale_ = false;
  std::vector<proto::Setting> settings_;
};

}  // namespace hil::client::wr8
