#pragma once
// The WR8 reference client for the real smart_vehicle_gui programs' dialects
// (profiles svgui-2019 and svgui-head), sans-I/O: login with the version's
// AUTH, v2019 tasks matched by COI and its unanswered SETTINGS, head CONTROL,
// SET and its read-back, the DATA streams with a stale flag per rate, and
// the MAP (docs/clients/wr8.md, "The real programs' dialects").
//
// It shares the actions, connection states, login, request and stale events
// of Wr8ClientCore (core.hpp); what only these dialects carry has its own
// events.

#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "client/wr8/core.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::client::wr8 {

namespace svgui = protocol::wr8::svgui;

struct SvguiConfig {
  svgui::Version version = svgui::Version::head;
  /// Without AUTH-REPLY this long after AUTH went out, the connection has
  /// failed: it is closed and retried. The head GUI gives up after 3 s.
  Duration login_timeout = link::seconds(3);
  /// false: the connection is usable as soon as AUTH is out, as the real
  /// v2019 GUI uses it (it sends tasks without waiting for a reply); an
  /// AUTH-REPLY that comes later is still reported as the login. For the
  /// real v2019 vehicle, which answers no login (docs/clients/wr8-client.md).
  bool wait_for_login = true;
  /// v2019: a task must end (ANSWER done or error) this long after it was
  /// sent, per task type (0 none, 1 forward, 2 wheels, 3 turn signals,
  /// 4 none). The vehicle sends no "started" and drops a task while busy
  /// without a word, so this is the only sign of a dropped task.
  std::array<Duration, proto::kTaskCount> task_timeout = {
      link::seconds(1), link::seconds(30), link::seconds(3), link::seconds(5), link::seconds(1)};
  /// head: SET waits this long for its ANSWER, SET-REQUEST for its SET.
  Duration answer_timeout = link::seconds(1);
  /// head: CONTROL goes out this often while control is held (the GUI's
  /// send timer runs at 10 Hz).
  Duration control_period = link::milliseconds(100);
  /// The least time between two packets sent. The real programs read
  /// whatever has arrived as one packet (v2019) or one packet per arrival
  /// (head), so packets sent back to back would reach them garbled or late;
  /// a packet due sooner waits, and a newer CONTROL replaces a waiting one.
  /// Zero sends everything at once.
  Duration send_gap = link::milliseconds(50);
  /// Without a packet of a stream this long its stale flag is raised: five
  /// periods of head's 50 ms and 1000 ms streams; v2019 DATA as the
  /// document's.
  Duration data_stale_after = link::milliseconds(500);
  Duration high_freq_stale_after = link::milliseconds(250);
  Duration low_freq_stale_after = link::seconds(5);
  /// Delays before reconnect attempt 1, 2, 3...; the last repeats forever.
  std::vector<Duration> reconnect_delays = {link::seconds(1), link::seconds(2), link::seconds(4),
                                            link::seconds(8)};
};

/// The AUTH text the GUI of `version` sends: "konnichiwa", and a NUL for head.
protocol::Bytes svgui_auth_text(svgui::Version version);

/// Lowest and highest COI the client uses for v2019 requests: the vehicle
/// takes COI 0 for "idle", and the GUI wraps from 126 back to 1.
inline constexpr std::uint8_t kFirstSvguiCoi = 1;
inline constexpr std::uint8_t kLastSvguiCoi = 126;

// ---- events only these dialects have ----

/// v2019 DATA: the live state as it came.
struct DataEvent {
  svgui::Data data;
};
/// head HIGH-FREQ DATA (every 50 ms).
struct HighFreqEvent {
  svgui::HighFreqData data;
};
/// head LOW-FREQ DATA (every second).
struct LowFreqEvent {
  svgui::LowFreqData data;
};
/// head MAP (once after login); the core keeps the last one.
struct MapEvent {
  svgui::Map map;
};
/// head: the settings the vehicle sent back after SET-REQUEST.
struct SetReadEvent {
  svgui::Set set;
};
/// A packet that decoded but matches nothing open: an ANSWER for no open
/// request (the v2019 vehicle sends ANSWER to every connection), a packet
/// only a GUI sends, or anything before login.
struct PacketIgnoredEvent {
  svgui::Message message;
  std::string why;
};

using SvguiEvent = std::variant<ConnectionEvent, LoginEvent, LoginFailedEvent, StaleEvent,
                                RequestEvent, ParseErrorEvent, DataEvent, HighFreqEvent,
                                LowFreqEvent, MapEvent, SetReadEvent, PacketIgnoredEvent>;

/// The operator's word for the request an event is about: "forward",
/// "wheels", "signals", "settings" (v2019); "set", "set-request" (head).
std::string svgui_request_name(const RequestEvent& r);

/// One line for a person, e.g. "request COI 3 forward timed_out (...)".
std::string describe(const SvguiEvent& event);

template <class T>
struct Received {
  T value;
  Time at{0};  ///< when the client got it
};

class SvguiClientCore : public LoginCore<SvguiEvent> {
 public:
  explicit SvguiClientCore(SvguiConfig config = {},
                           std::shared_ptr<CommLog> log = std::make_shared<CommLog>());

  // ---- operator ----
  void connect(Time now);
  void disconnect(Time now);

  /// v2019 TASK type 1, 2 or 3. Matched by COI; ends completed (ANSWER 2),
  /// error (ANSWER 0) or timed_out.
  SubmitResult forward(Time now, std::int32_t distance_cm);
  SubmitResult wheels(Time now, std::int32_t angle_deg);
  SubmitResult signals(Time now);
  /// v2019 SETTINGS (p, i, d, servo zero). No answer ever comes: its only
  /// event is `sent`, and it leaves no request open.
  SubmitResult settings(Time now, const std::array<std::int32_t, 4>& values);

  /// head CONTROL: sends the axes now and every control_period until
  /// release_control(). Each axis in -1..1 (x steering, y engine).
  Refusal control(Time now, double x_axis, double y_axis);
  /// head: one CONTROL 0 0 and the repetition stops. Nothing when not held.
  Refusal release_control(Time now);
  /// head SET: waits for ANSWER (1 applied: completed; 0: error). One at a
  /// time (busy while one is open); its RequestEvent has kind settings, COI 0.
  SubmitResult set(Time now, const svgui::Set& values);
  /// head SET-REQUEST: waits for the vehicle's SET (SetReadEvent, then a
  /// RequestEvent completed of task get_settings, COI 0).
  SubmitResult set_request(Time now);

  // ---- driver (and on_connect_failed) ----
  void on_connected(Time now);
  void on_bytes(Time now, protocol::ByteView bytes);
  void on_closed(Time now);
  void on_timer(Time now);
  std::optional<Time> next_wakeup() const;

  // ---- state (and state(), log(), take_actions(), take_events()) ----
  svgui::Version version() const { return config_.version; }
  const std::optional<Received<svgui::Data>>& data() const { return data_; }
  const std::optional<Received<svgui::HighFreqData>>& high_freq() const { return high_freq_; }
  const std::optional<Received<svgui::LowFreqData>>& low_freq() const { return low_freq_; }
  const std::optional<svgui::Map>& map() const { return map_; }
  /// The settings the vehicle last sent back (head).
  const std::optional<svgui::Set>& read_settings() const { return read_settings_; }
  bool stale(DataStream stream) const { return streams_[index(stream)].stale; }
  /// Packets waiting for send_gap.
  std::size_t queued() const { return outbox_.size(); }
  /// The axes CONTROL repeats, while held.
  const std::optional<svgui::Control>& held_control() const { return control_; }
  std::size_t open_requests() const;
  const SvguiConfig& config() const { return config_; }

 private:
  struct Pending {
    RequestKind kind = RequestKind::task;
    proto::TaskCode task = proto::TaskCode::check;
    Time deadline{0};
  };
  struct Stream {
    std::optional<Time> last;  // on this connection
    bool stale = false;
  };
  static std::size_t index(DataStream s) { return static_cast<std::size_t>(s); }

  SubmitResult send_task(Time now, proto::TaskCode type, std::vector<std::int32_t> params);
  SubmitResult send_head_request(Time now, RequestKind kind, proto::TaskCode task,
                                 const svgui::Message& message);
  std::optional<std::uint8_t> free_coi() const;
  /// Sends `message`, or queues it until send_gap has passed.
  void send(Time now, const svgui::Message& message);
  void write(Time now, const svgui::Message& message);
  bool may_send(Time now) const;
  void flush_outbox(Time now);
  void handle(Time now, const svgui::Message& message);
  void on_answer(Time now, const svgui::Answer& answer, const svgui::Message& message);
  void fresh(Time now, DataStream stream);
  void finish(std::optional<Pending>& slot, std::uint8_t coi, RequestState state,
              std::string note = {});
  void ignored(Time now, const svgui::Message& message, std::string why);
  void end_connection(Time now);
  void become_connected(Time now);
  Duration stale_after(DataStream s) const;

  // connection_'s reconnect count goes back to 0 at login.
  SvguiConfig config_;
  svgui::Decoder decoder_;
  std::vector<svgui::Item> items_;
  bool logged_in_ = false;  ///< an AUTH-REPLY came on this connection

  // v2019: tasks by COI.
  std::uint8_t next_coi_ = kFirstSvguiCoi;
  std::array<std::optional<Pending>, 256> pending_{};
  // head: the open SET and SET-REQUEST (no COI on the wire).
  std::optional<Pending> set_pending_;
  std::optional<Pending> set_request_pending_;

  std::optional<svgui::Control> control_;
  std::optional<Time> next_control_;

  std::deque<svgui::Message> outbox_;  // packets waiting for send_gap
  std::optional<Time> last_sent_;      // on this connection

  std::optional<Received<svgui::Data>> data_;
  std::optional<Received<svgui::HighFreqData>> high_freq_;
  std::optional<Received<svgui::LowFreqData>> low_freq_;
  std::optional<svgui::Map> map_;
  std::optional<svgui::Set> read_settings_;
  std::array<Stream, 3> streams_{};
};

}  // namespace hil::client::wr8
