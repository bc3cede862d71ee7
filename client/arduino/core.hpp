#pragma once
// The Arduino robot client as a sans-I/O core: one framed request at a time
// with SEQ matching, timeout doubling, BAD_CS resends, and the link state
// machine (OPEN, DEGRADED, RECONNECTING, DOWN, in the shared vocabulary
// connected, degraded, reconnecting, down). It takes inputs with the
// time and hands back actions, events and its next wakeup (docs/clients/arduino.md).

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "client/common/connection.hpp"
#include "link/time.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/arduino/message.hpp"
#include "protocol/arduino/reply.hpp"

namespace hil::client::arduino {

using link::Duration;
using link::Time;
using protocol::Bytes;
using protocol::ByteView;

struct ClientConfig {
  /// The board's dialect (its profile): `firmware`, the real sketch, sends
  /// a request without an argument with a one-space payload and reads the
  /// sketch's replies; `readme` frames and reads the README's examples. The
  /// default is the one `hil mock arduino` plays by default.
  protocol::arduino::Dialect dialect = protocol::arduino::kDefaultDialect;
  /// Timeout of the first attempt; each retry doubles it.
  Duration base_timeout = link::milliseconds(600);
  /// Retries after the first attempt (timeouts 0.6, 1.2, 2.4, 4.8 s by default).
  int max_retries = 3;
  /// NACK BAD_CS resends of one request before the NACK is returned.
  int max_bad_cs_resends = 3;
  /// A PING is sent after this long without an exchange while OPEN; 0: never.
  Duration health_check_interval = link::seconds(5);
  /// Wait before the first reconnect attempt; doubles for each further one.
  Duration reconnect_base_delay = link::milliseconds(500);
  /// Failed reconnect attempts after which the link is DOWN.
  int max_reconnect_attempts = 4;
  /// Retries of the PING that proves a reopened port (0.6, 1.2, 2.4 s).
  int reconnect_ping_retries = 2;
};

/// The link's states, in the shared vocabulary: disconnected (closed),
/// connecting (opening), connected (open), degraded, reconnecting, down.
using client::ConnectionState;
using client::to_string;
/// The link state as docs/clients/arduino.md and the program name it:
/// "CLOSED", "OPENING", "OPEN", "DEGRADED", "RECONNECTING", "DOWN".
std::string_view link_name(ConnectionState s);

enum class ResultCode : std::uint8_t {
  ok,               ///< ACK; `info` holds its payload
  nack,             ///< NACK; `nack` holds the code or text
  timeout,          ///< no valid answer after every attempt
  link_down,        ///< the link was closed, lost or DOWN
  invalid_request,  ///< the request cannot be framed (V outside 0..255, bad token)
};
std::string_view to_string(ResultCode c);

struct Result {
  ResultCode code = ResultCode::ok;
  std::string info;  ///< ACK payload
  /// The ACK payload's meaning in the board's dialect, the same type for
  /// both ("B:232" and "232" are SonarReply{232}); empty for a raw request
  /// hil does not type, or a text the dialect does not answer that request with.
  std::optional<protocol::arduino::Reply> reply;
  std::optional<protocol::arduino::Nack> nack;
  std::string detail;  ///< why, for a person
  int attempts = 0;    ///< timed attempts sent (BAD_CS resends not counted)
  int bad_cs_resends = 0;
  std::optional<std::uint8_t> seq;
};

using RequestId = std::uint64_t;

// ---- actions for the driver ----
struct OpenPort {};
struct SendFrame {
  Bytes bytes;
  std::uint8_t seq = 0;
};
struct ClosePort {};
using Action = std::variant<OpenPort, SendFrame, ClosePort>;

// ---- events for a UI or a test ----
struct RequestDone {
  RequestId id = 0;
  Result result;
};
struct LinkChanged {
  ConnectionState from = ConnectionState::disconnected;
  ConnectionState to = ConnectionState::disconnected;
  Time at{0};
  std::string reason;
};
/// A complete frame (or frame-like bytes) that came in; for the log.
struct FrameReceived {
  Bytes raw;
  std::optional<std::uint8_t> seq;
  bool valid = false;  ///< decoded cleanly
};
using Event = std::variant<RequestDone, LinkChanged, FrameReceived>;

class ArduinoClientCore {
 public:
  explicit ArduinoClientCore(ClientConfig config = {});
  virtual ~ArduinoClientCore() = default;
  ArduinoClientCore(const ArduinoClientCore&) = default;
  ArduinoClientCore& operator=(const ArduinoClientCore&) = default;
  ArduinoClientCore(ArduinoClientCore&&) = default;
  ArduinoClientCore& operator=(ArduinoClientCore&&) = default;

  // ---- from the user ----
  /// Asks for the port to be opened (OpenPort); OPEN once on_connected().
  void open(Time now);
  /// Closes the port; pending requests end with link_down.
  void close(Time now);

  /// Queues a request; requests go out one at a time, in order.
  RequestId request(Time now, protocol::arduino::Body body);
  /// A token as the robot's CLI takes it: "PING", "V:160", "R:-90" (the
  /// command is upper-cased). It goes to the robot as typed, out-of-range or
  /// unknown ones too ("V:999" is answered NACK BAD_V by the board); only a
  /// token that cannot be framed (empty, or with ^ $ * |) ends invalid_request.
  RequestId raw(Time now, std::string_view token);
  RequestId ping(Time now) { return request(now, protocol::arduino::Ping{}); }
  RequestId status(Time now) { return request(now, protocol::arduino::StatusRequest{}); }
  RequestId set_v(Time now, int pwm) { return request(now, protocol::arduino::SetSpeed{pwm}); }
  RequestId move_cm(Time now, int cm) { return request(now, protocol::arduino::Move{cm}); }
  RequestId rotate_deg(Time now, int deg) { return request(now, protocol::arduino::Rotate{deg}); }
  RequestId stop(Time now) { return request(now, protocol::arduino::Stop{}); }
  RequestId sonar(Time now) { return request(now, protocol::arduino::SonarRead{}); }
  RequestId ir(Time now) { return request(now, protocol::arduino::IrRead{}); }
  RequestId help(Time now) { return request(now, protocol::arduino::Help{}); }

  // ---- from the driver ----
  void on_connected(Time now);
  void on_connect_failed(Time now, std::string_view why);
  void on_bytes(Time now, ByteView bytes);
  /// The port closed (by the peer, or after a ClosePort).
  void on_closed(Time now);
  /// Call at (or after) next_wakeup().
  void on_timer(Time now);
  std::optional<Time> next_wakeup() const;

  std::vector<Action> take_actions();
  std::vector<Event> take_events();

  ConnectionState state() const { return state_; }
  bool busy() const { return inflight_.has_value(); }
  std::size_t queued() const { return queue_.size(); }
  /// The SEQ the next request will carry.
  std::uint8_t next_seq() const { return next_seq_; }
  /// Frames with another SEQ ignored so far, and complete frames that did not decode.
  std::uint64_t stale_frames() const { return stale_frames_; }
  std::uint64_t parse_errors() const { return parse_errors_; }
  const ClientConfig& config() const { return config_; }

 protected:
  // The protocol's rules, each decided here alone (docs/clients/arduino.md).
  // A test overrides one to plant a known bug (tests/property/arduino_planted_bug.hpp).

  /// The timeout rule: attempt `attempt` (0: the first) waits base_timeout x 2^attempt.
  virtual Duration timeout_of(int attempt) const;
  /// The matching rule: only a reply carrying `request_seq` answers the request sent with it.
  virtual bool answers(std::uint8_t request_seq, const protocol::arduino::Message& reply) const;
  /// The resend rule: a NACK saying the line damaged the request (BAD_CS) resends it at once.
  virtual bool resend_on(const protocol::arduino::Nack& nack) const;

 private:
  enum class Purpose : std::uint8_t { user, health_check, reconnect_check };
  /// A typed request, or a raw token hil does not type, framed as given.
  using Payload = std::variant<protocol::arduino::Body, protocol::arduino::Envelope>;
  struct Pending {
    RequestId id = 0;
    Purpose purpose = Purpose::user;
    Payload what;
  };
  struct Inflight {
    Pending pending;
    std::uint8_t seq = 0;
    Bytes frame;
    int attempt = 0;  // 0: the first
    int max_retries = 0;
    int bad_cs_resends = 0;
    Time deadline{0};
  };

  static Result lost_result(const Inflight& lost, ResultCode code, const std::string& detail);
  Bytes frame_of(const Pending& pending, std::uint8_t seq) const;
  /// Queues the operator's request `id`, or completes it link_down at once
  /// while the link is closed or down.
  void queue_user(Time now, RequestId id, Payload what);
  void pump(Time now);
  void send_current(Time now);
  void finish(Time now, Result result);
  void set_state(Time now, ConnectionState to, std::string reason);
  void link_failed(Time now, std::string reason);
  void reconnect_failed(Time now, std::string reason);
  void fail_all(Time now, ResultCode code, const std::string& detail);
  void complete(RequestId id, Result result);
  void handle_message(Time now, const protocol::arduino::Message& m);

  ClientConfig config_;
  ConnectionState state_ = ConnectionState::disconnected;
  bool connected_ = false;
  std::deque<Pending> queue_;
  std::optional<Inflight> inflight_;
  std::uint8_t next_seq_ = 0;
  RequestId next_id_ = 1;
  Time last_exchange_{0};
  // Its attempt count is the failed reopen attempts since the link degraded.
  ReconnectSchedule reconnect_;
  protocol::arduino::Decoder decoder_;
  std::vector<protocol::arduino::Item> items_;
  std::vector<Action> actions_;
  std::vector<Event> events_;
  std::uint64_t stale_frames_ = 0;
  std::uint64_t parse_errors_ = 0;
};

}  // namespace hil::client::arduino
