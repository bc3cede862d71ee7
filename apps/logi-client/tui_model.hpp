#pragma once
// The logi-client terminal UI's state and key handling, free of ncurses and
// of clocks: keys and session events in (with the time), calls on the
// session and a description of the screen out.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "client/logi/core.hpp"
#include "link/time.hpp"

namespace hil::apps::logi_client {

namespace logi = client::logi;
namespace proto = protocol::logi;
using link::Duration;
using link::Time;

using client::LogFormat;

/// What the screen asks of the LOGI session (LogiSession in the program, a
/// mock in tests).
class SessionControl {
 public:
  virtual ~SessionControl() = default;
  /// Connects to host:port (a different address than before replaces the connection).
  virtual void connect(const std::string& host, std::uint16_t port) = 0;
  virtual void disconnect() = 0;
  virtual logi::SubmitResult submit(const proto::Message& command) = 0;
  virtual logi::SubmitResult press(proto::Direction direction) = 0;
  virtual logi::SubmitResult release() = 0;
  virtual logi::SubmitResult emergency_stop() = 0;
  virtual logi::SubmitResult confirm_resend(logi::RequestId request) = 0;
  /// Commands queued or waiting for their feedback.
  virtual bool busy() const = 0;
  /// Writes the communication log to a file; returns what to tell the operator.
  virtual std::string save_log(LogFormat format) = 0;
};

/// Key codes the model understands: printable ASCII and control characters
/// as themselves, the special keys below (the view maps its library's codes).
namespace key {
/// Control characters.
enum : int { kCtrlC = 3, kEnter = '\n', kCtrlQ = 17, kEscape = 27, kBackspace = 127 };
/// Keys without a character: codes above every character's.
enum : int { kUp = 0x1001, kDown, kLeft, kRight, kPageUp, kPageDown, kHome, kEnd, kF10 = 0x1010 };
}  // namespace key

struct TuiModelConfig {
  std::string host = "127.0.0.1";
  std::uint16_t port = 9000;
  bool connect_at_start = true;
  /// Held mode: a direction is released when no key repeat arrived within
  /// this long after the first press (covers the longest usual auto-repeat delay)...
  Duration first_repeat_window = link::milliseconds(700);
  /// ...or within this long after the latest repeat (repeats come every 30-40 ms).
  Duration repeat_window = link::milliseconds(200);
  /// Start in latched mode (a press starts, the same key or stop ends it).
  bool latched = false;
  /// On quit: how long to wait for the emergency stop's feedback before closing.
  Duration quit_grace = link::seconds(1);
  /// Log lines kept for the log panel.
  std::size_t log_lines_kept = 2000;
};

enum class Style : std::uint8_t { normal, dim, bold, good, warning, alert };

struct TextLine {
  std::string text;
  Style style = Style::normal;
  friend bool operator==(const TextLine&, const TextLine&) = default;
};

struct Panel {
  std::string title;
  std::vector<TextLine> lines;
};

/// What the screen shows; the view decides where.
struct Render {
  TextLine header;                   ///< address and connection state
  std::optional<std::string> stale;  ///< the stale warning, when raised
  Panel status;                      ///< every STAT field
  Panel controls;                    ///< mode, speed, station, driving, pending confirmations
  Panel log;                         ///< the visible log lines, oldest first
  TextLine message;                  ///< the latest notice, refusal or result
  std::vector<std::string> help;     ///< key reminders, most important first
  std::optional<std::string> edit;   ///< the field being edited, with its text
};

/// The screen's model. Every input carries the current time; call on_time()
/// at next_wakeup().
class TuiModel {
 public:
  TuiModel(SessionControl& control, TuiModelConfig config = {});

  /// Connects if the configuration says so.
  void start(Time now);
  /// One key (see the `key` codes).
  void on_key(Time now, int code);
  void on_event(Time now, const logi::Event& event);
  /// New entries of the communication log, oldest first.
  void on_log(const std::vector<logi::LogEntry>& entries);
  /// Runs what is due: hold release, the end of quitting.
  void on_time(Time now);
  std::optional<Time> next_wakeup() const;
  /// Quit (a key, or SIGINT/SIGTERM): emergency stop, then disconnect once
  /// its feedback came or quit_grace passed.
  void quit(Time now);
  /// The program may end (quit finished and the session was disconnected).
  bool done() const { return done_; }

  /// The screen; `log_rows` is how many log lines fit.
  Render render(Time now, std::size_t log_rows) const;

  // ---- state, for the view and tests ----
  int speed_percent() const { return speed_percent_; }
  int station() const { return station_; }
  bool latched() const { return latched_; }
  std::optional<proto::Direction> held() const { return held_; }
  bool stale() const { return stale_; }
  bool estop_pending() const { return estop_pending_; }
  const std::string& host() const { return host_; }
  std::uint16_t port() const { return port_; }
  const std::string& message() const { return message_.text; }
  logi::ConnectionState connection() const { return connection_; }

 private:
  enum class Field : std::uint8_t { none, host, port, speed, save };

  void emergency_stop(Time now);
  void direction_key(Time now, proto::Direction direction);
  void stop_key(Time now);
  void release_held(Time now);
  void edit_key(Time now, int code);
  void commit_edit(Time now);
  void send_speed(Time now);
  void toggle_mode(Time now);
  void toggle_connection(Time now);
  void confirm(Time now);
  void finish_quit_if_ready(Time now);
  void say(std::string text, Style style = Style::normal);
  bool refused(const logi::SubmitResult& result, std::string_view what);
  void scroll_log(long delta);

  SessionControl& control_;
  TuiModelConfig config_;

  std::string host_;
  std::uint16_t port_ = 0;
  logi::ConnectionState connection_ = logi::ConnectionState::disconnected;
  int reconnect_attempt_ = 0;

  // Operator's settings.
  int speed_percent_ = 50;
  int station_ = 1;
  bool latched_ = false;
  std::optional<proto::Mode> mode_shown_;  // latest of STAT mode and MD sent

  // Editing a field.
  Field field_ = Field::none;
  std::string edit_text_;

  // Holding a direction.
  std::optional<proto::Direction> held_;
  bool repeats_seen_ = false;
  Time release_at_{0};

  // What the car and session said.
  std::optional<proto::Status> status_;
  Time status_at_{0};
  bool stale_ = false;
  bool movement_enabled_ = false;
  std::string movement_reason_ = "not connected";
  std::string last_command_;
  struct Confirmable {
    logi::RequestId request = 0;
    std::string command;
  };
  std::vector<Confirmable> confirmable_;
  bool estop_pending_ = false;  // pressed while not connected: sent on connect
  TextLine message_;

  // The log panel.
  std::vector<TextLine> log_;
  std::uint64_t log_total_ = 0;
  std::size_t log_scroll_ = 0;  // lines above the newest (0: follow)

  // Quitting.
  bool quitting_ = false;
  Time quit_deadline_{0};
  bool done_ = false;
};

/// One log entry as the log panel shows it: "  12.345 TX   LOGI:SP:050:D7#  SetSpeed percent=50".
std::string format_log_line(const logi::LogEntry& entry);

/// The direction a key drives, if any (q w e / a s d / z x c, arrows, [ ]).
std::optional<proto::Direction> direction_for_key(int code);

}  // namespace hil::apps::logi_client
