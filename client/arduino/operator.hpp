#pragma once
// The Arduino robot's operator language (one command per line: raw protocol
// tokens, lower-case aliases, client-side commands, waits) and a runner that
// carries out a list of such commands on an ArduinoSession, one after another
// (docs/clients/arduino-client.md).

#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "client/arduino/session.hpp"
#include "client/common/operator_text.hpp"
#include "link/executor.hpp"
#include "link/time.hpp"
#include "protocol/arduino/message.hpp"

namespace hil::client::arduino {

// ---- the commands ----

/// A request for the robot (PING, STATUS, V, M, R, S, B, I, HELP).
struct RobotRequest {
  protocol::arduino::Body body;
  /// A token in the robot CLI's raw form ("V:999", "X:1") that hil would not
  /// type: it goes to the robot as given and the board answers it (`body`
  /// is unused then). The spaced form ("V 999") is checked instead.
  std::optional<std::string> raw = std::nullopt;
  friend bool operator==(const RobotRequest&, const RobotRequest&) = default;
};
/// `wait 500ms`: nothing happens for this long (scripts pace themselves with it).
struct WaitCommand {
  Duration duration{0};
  friend bool operator==(const WaitCommand&, const WaitCommand&) = default;
};
/// `history`: the frame log so far, as text.
struct HistoryCommand {
  friend bool operator==(const HistoryCommand&, const HistoryCommand&) = default;
};
/// `save-log PATH`: the frame log written to a file, its format by extension.
struct SaveLogCommand {
  std::string path;
  friend bool operator==(const SaveLogCommand&, const SaveLogCommand&) = default;
};
/// `reconnect`: close the port and open it again after the session's
/// reconnect_base_delay (0.5 s by default), as an automatic reconnect does.
struct ReconnectCommand {
  friend bool operator==(const ReconnectCommand&, const ReconnectCommand&) = default;
};
/// `quit` / `exit`: nothing after it runs.
struct QuitCommand {
  friend bool operator==(const QuitCommand&, const QuitCommand&) = default;
};

using OperatorCommand = std::variant<RobotRequest, WaitCommand, HistoryCommand, SaveLogCommand,
                                     ReconnectCommand, QuitCommand>;

/// The canonical spelling of a command: "PING", "V 160", "wait 1s", "save-log a.csv".
std::string to_text(const OperatorCommand& command);

// ---- parsing ----

/// Where a line is wrong, e.g. "V needs a number 0..255".
using OperatorParseError = client::LineError;
/// One parsed line: a command (`action`), nothing (blank or a comment), or an error.
using OperatorLine = client::ParseResult<OperatorCommand>;

/// Parses one line. Command words ignore letter case ("PING", "ping", "v 160",
/// "V:160"); '#' starts a comment that runs to the end of the line.
OperatorLine parse_operator_line(std::string_view line);

/// A script's command with the line it came from.
struct ScriptStep {
  OperatorCommand command;
  std::size_t line = 0;  ///< 1-based
};

struct Script {
  std::vector<ScriptStep> steps;
  std::vector<client::ScriptError> errors;  ///< every line that did not parse, in order
  bool ok() const { return errors.empty(); }
  std::vector<OperatorCommand> commands() const;
};

/// Parses a script's text; `file` names it in errors.
Script parse_script(std::string_view text, const std::string& file);
/// Reads and parses a script file; a file that cannot be read is one error.
Script load_script(const std::string& path);

// ---- running ----

/// What became of one command the runner carried out.
struct CommandOutcome {
  std::size_t index = 0;  ///< 0-based, counting every command given to the runner
  OperatorCommand command;
  bool ok = true;
  std::optional<Result> result;  ///< for robot requests
  /// What to show a person: "ACK 160", "NACK BUSY", the history, "saved 4
  /// frames to a.csv"; empty for a wait or quit.
  std::string text;
  Time started{0};
  Time finished{0};
};

/// "ACK OK", "NACK BAD_V", "TIMEOUT (no answer after 4 attempts)",
/// "LINK DOWN (...)", "INVALID (...)".
std::string describe_result(const Result& result);
/// "V 160 -> ACK 160"; for client commands their text (may be empty).
std::string describe_outcome(const CommandOutcome& outcome);

/// Carries out operator commands on a session one after another under either
/// driver: each robot request waits for its Result, a wait for its duration,
/// a reconnect for the link to be OPEN (or DOWN) again.
class OperatorRunner {
 public:
  struct Options {
    /// Go on after a failed command instead of dropping the rest.
    bool keep_going = false;
  };
  using OutcomeHandler = std::function<void(const CommandOutcome&)>;

  /// The runner installs the session's event handler (it watches the link
  /// for `reconnect`); pass your own through set_event_handler. `session`
  /// and `executor` must outlive the runner.
  OperatorRunner(ArduinoSession& session, link::Executor& executor, Options options);
  OperatorRunner(ArduinoSession& session, link::Executor& executor)
      : OperatorRunner(session, executor, Options{}) {}
  ~OperatorRunner();
  OperatorRunner(const OperatorRunner&) = delete;
  OperatorRunner& operator=(const OperatorRunner&) = delete;

  void set_outcome_handler(OutcomeHandler handler) { on_outcome_ = std::move(handler); }
  /// Runs whenever the runner has nothing left to do (queue empty or halted).
  void set_idle_handler(std::function<void()> handler) { on_idle_ = std::move(handler); }
  /// The session's events, passed on after the runner looked at them.
  void set_event_handler(ArduinoSession::EventHandler handler) { on_event_ = std::move(handler); }

  /// Queues commands; they start at once if nothing runs. Ignored once halted.
  void add(OperatorCommand command);
  void add(const std::vector<OperatorCommand>& commands);

  /// Nothing running and nothing queued (or halted).
  bool idle() const { return !running_ && (queue_.empty() || halted_); }
  /// A failure (without keep_going) or a quit ended the run.
  bool halted() const { return halted_; }
  bool quit_requested() const { return quit_; }
  std::size_t failures() const { return failures_; }
  std::size_t completed() const { return completed_; }

 private:
  struct Queued {
    std::size_t index = 0;
    OperatorCommand command;
  };
  void pump();
  void start(Queued queued);
  void finish(CommandOutcome outcome);
  void on_session_event(const Event& event);
  void finish_reconnect(bool ok, const std::string& reason);

  ArduinoSession& session_;
  link::Executor& executor_;
  Options options_;
  std::deque<Queued> queue_;
  std::optional<CommandOutcome> current_;  // the running command's outcome so far
  bool running_ = false;
  bool pumping_ = false;
  bool halted_ = false;
  bool quit_ = false;
  bool awaiting_reconnect_ = false;
  std::size_t next_index_ = 0;
  std::size_t failures_ = 0;
  std::size_t completed_ = 0;
  link::Executor::TimerId wait_timer_ = 0;
  OutcomeHandler on_outcome_;
  std::function<void()> on_idle_;
  ArduinoSession::EventHandler on_event_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::client::arduino
