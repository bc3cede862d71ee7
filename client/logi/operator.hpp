#pragma once
// The LOGI operator-action vocabulary ("speed 50", "press FWD", "wait 1s"):
// its parser, and a runner that carries actions out on a LogiSession using
// only the session's executor, so it runs alike in real and virtual time.

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "client/common/operator_text.hpp"
#include "client/logi/core.hpp"
#include "client/logi/session.hpp"
#include "link/executor.hpp"

namespace hil::client::logi {

/// One operator action each; the wire frame each sends is in docs/clients/logi-client.md.
namespace op {
struct Connect {
  friend bool operator==(const Connect&, const Connect&) = default;
};
struct Disconnect {
  friend bool operator==(const Disconnect&, const Disconnect&) = default;
};
struct Speed {
  int percent = 0;  ///< 0..100
  friend bool operator==(const Speed&, const Speed&) = default;
};
struct SetMode {
  proto::Mode mode = proto::Mode::automatic;
  friend bool operator==(const SetMode&, const SetMode&) = default;
};
struct Press {
  proto::Direction direction = proto::Direction::stop;
  friend bool operator==(const Press&, const Press&) = default;
};
struct Release {
  friend bool operator==(const Release&, const Release&) = default;
};
struct Station {
  int station = 0;  ///< 0..999 (the car accepts 1 and 2)
  friend bool operator==(const Station&, const Station&) = default;
};
struct Run {
  friend bool operator==(const Run&, const Run&) = default;
};
struct Stop {
  friend bool operator==(const Stop&, const Stop&) = default;
};
struct EmergencyStop {
  friend bool operator==(const EmergencyStop&, const EmergencyStop&) = default;
};
struct Wait {
  link::Duration duration{0};
  friend bool operator==(const Wait&, const Wait&) = default;
};
struct Confirm {
  friend bool operator==(const Confirm&, const Confirm&) = default;
};
}  // namespace op

using OperatorAction =
    std::variant<op::Connect, op::Disconnect, op::Speed, op::SetMode, op::Press, op::Release,
                 op::Station, op::Run, op::Stop, op::EmergencyStop, op::Wait, op::Confirm>;

/// The action written the canonical way ("speed 50", "press FWD", "wait 1.5s").
std::string to_string(const OperatorAction& action);

/// A duration as a `wait` takes it: "1.5s", "500ms", "2m".
inline std::string format_duration(link::Duration d) {
  return client::duration_text(d, client::DurationStyle::largest_unit);
}

using OperatorSyntaxError = client::LineError;
/// An action, nothing (a blank line or a comment), or an error.
using OperatorParseResult = client::ParseResult<OperatorAction>;

/// Parses one line: an action, optionally followed by a `#` comment.
/// Action words, modes and directions are case-insensitive.
OperatorParseResult parse_operator_action(std::string_view line);

/// A duration with a unit: "500ms", "1s", "1.5s", "2m" (at most 24 h).
std::optional<link::Duration> parse_duration(std::string_view text);

/// One action of a script and where it came from.
struct OperatorStep {
  int line = 0;      ///< 1-based line in the script
  std::string text;  ///< the line as written, without comment and outer blanks
  OperatorAction action;
};

struct OperatorScript {
  std::vector<OperatorStep> steps;
  std::vector<client::ScriptError> errors;  ///< every line that did not parse, in order
  bool ok() const { return errors.empty(); }
};

/// Parses a whole script, one action per line; every bad line is an error.
OperatorScript parse_operator_script(std::string_view text, std::string_view file_name);

/// What became of one action.
struct ActionResult {
  std::size_t index = 0;  ///< 0-based position in the list
  int line = 0;
  std::string text;
  bool ok = false;
  std::string reason;  ///< why it failed (empty when ok)
  Time started{0};
  Time ended{0};
};

struct RunSummary {
  bool ok = false;         ///< every action that ran succeeded and none was left out
  std::size_t ran = 0;     ///< actions that ended (ok or failed)
  std::size_t failed = 0;  ///< of those, how many failed
  bool cancelled = false;  ///< cancel() ended the run
};

struct OperatorRunnerOptions {
  /// How long `connect` waits for the Connected state (reconnects included).
  link::Duration connect_timeout = link::seconds(10);
  /// Go on after a failed action (the run still reports failure).
  bool continue_on_error = false;
  /// An uncertain ST:RUN or GS seen before this runner started, for its
  /// `confirm` (a program that runs one runner per action keeps it between
  /// them).
  std::optional<RequestId> confirmable;
};

/// Executes operator actions one after another on a LogiSession. Feed it
/// every event of the session's sink through on_event(); it reports each
/// action's result and then the end of the run. Timing comes only from the
/// executor, so under the virtual-time driver every time is exact.
class OperatorRunner {
 public:
  using ResultSink = std::function<void(const ActionResult&)>;
  using DoneSink = std::function<void(const RunSummary&)>;

  /// `session` and `executor` (the session's) must outlive the runner.
  OperatorRunner(LogiSession& session, link::Executor& executor, std::vector<OperatorStep> steps,
                 OperatorRunnerOptions options = {}, ResultSink on_result = {},
                 DoneSink on_done = {});
  ~OperatorRunner();
  OperatorRunner(const OperatorRunner&) = delete;
  OperatorRunner& operator=(const OperatorRunner&) = delete;

  /// Begins with the first action (on a later executor turn).
  void start();
  /// Every event of the session, in order.
  void on_event(Time now, const Event& event);
  /// Ends the run now: the action under way fails as "cancelled" (also one
  /// whose first turn had not come yet: start() and the end of an action
  /// begin the next on a later turn), none after it starts. Sends nothing
  /// to the car.
  void cancel();

  bool finished() const { return finished_; }
  const std::vector<ActionResult>& results() const { return results_; }
  /// The index of the action under way, if any.
  std::optional<std::size_t> current() const;

 private:
  void begin(std::size_t index);
  void finish_action(bool ok, std::string reason);
  void finish_run(bool cancelled);
  /// The awaited requests all ended: success if enough were accepted.
  void check_requests();
  void await(RequestId id);
  void start_timer(link::Duration d, std::function<void()> then);
  void stop_timer();
  std::string refused(Refusal r) const;

  LogiSession& session_;
  link::Executor& executor_;
  std::vector<OperatorStep> steps_;
  OperatorRunnerOptions options_;
  ResultSink on_result_;
  DoneSink on_done_;

  std::vector<ActionResult> results_;
  std::size_t next_ = 0;
  bool active_ = false;  // an action is under way
  bool started_ = false;
  /// The action whose begin() is posted and has not run yet.
  std::optional<std::size_t> due_;
  bool finished_ = false;
  bool any_failed_ = false;
  Time action_started_{0};

  // Command actions: the requests awaited and how each ended.
  enum class Await : std::uint8_t { none, requests, connected };
  Await await_ = Await::none;
  bool collect_sent_ = false;  // an emergency stop: every request sent during the call
  std::vector<RequestId> awaited_;
  std::vector<CommandEvent> outcomes_;         // terminal CommandEvents since the action began
  std::optional<RequestId> last_confirmable_;  // uncertain ST:RUN / GS awaiting confirmation
  std::string last_connect_problem_;

  link::Executor::TimerId timer_ = 0;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::client::logi
