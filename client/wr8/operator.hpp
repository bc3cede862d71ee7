#pragma once
// The WR8 operator's vocabulary (connect, drive 30, set p=1.5, wait 1s, ...):
// parsing a line or a script into typed actions, and a runner that carries
// them out on a Wr8Session under either driver (docs/clients/wr8-client.md).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "client/wr8/session.hpp"
#include "link/executor.hpp"

namespace hil::client::wr8 {

namespace op {
/// Opens the connection and logs in.
struct Connect {
  friend bool operator==(const Connect&, const Connect&) = default;
};
struct Disconnect {
  friend bool operator==(const Disconnect&, const Disconnect&) = default;
};
struct Drive {
  std::int32_t distance_cm = 0;
  friend bool operator==(const Drive&, const Drive&) = default;
};
struct Turn {
  std::int32_t angle_deg = 0;
  friend bool operator==(const Turn&, const Turn&) = default;
};
/// Any task code with its parameters, as the profile presents them.
struct RawTask {
  proto::TaskCode code = proto::TaskCode::check;
  std::vector<proto::Word> params;
  friend bool operator==(const RawTask&, const RawTask&) = default;
};
struct GetSettings {
  friend bool operator==(const GetSettings&, const GetSettings&) = default;
};
struct SetSettings {
  std::vector<proto::Setting> settings;
  friend bool operator==(const SetSettings&, const SetSettings&) = default;
};
struct Wait {
  Duration duration{0};
  friend bool operator==(const Wait&, const Wait&) = default;
};
/// Waits for the next DATA packet.
struct WaitData {
  friend bool operator==(const WaitData&, const WaitData&) = default;
};
}  // namespace op

using OperatorAction = std::variant<op::Connect, op::Disconnect, op::Drive, op::Turn, op::RawTask,
                                    op::GetSettings, op::SetSettings, op::Wait, op::WaitData>;

/// The action as a line the parser reads back ("drive 30", "set p=1.5").
std::string to_text(const OperatorAction& action,
                    const proto::Profile& profile = proto::default_profile());

struct LineError {
  std::size_t column = 1;  ///< 1-based column of the offending token
  std::string message;     ///< what was wrong and what was expected
};

/// One parsed line: an action, nothing (blank or `#` comment), or an error.
struct ParsedLine {
  std::optional<OperatorAction> action;
  std::optional<LineError> error;
};

/// Parses one line of the document profile's vocabulary. Never throws on
/// input. A word only the real programs' profiles have is an error naming
/// the profiles that take it.
ParsedLine parse_operator_line(std::string_view line,
                               const proto::Profile& profile = proto::default_profile());

/// The error for `word`, a word `profile` does not take: which profiles
/// take it, if any, and the words `profile` takes (`vocabulary`).
std::string word_not_in_profile(std::string_view word, std::string_view profile,
                                std::string_view vocabulary);

/// Splits a line into its first word (lowercased) and the column after it,
/// so a program can add its own commands in front of the vocabulary.
std::string first_word(std::string_view line);

struct ScriptStep {
  int line = 0;
  OperatorAction action;
};

struct ScriptError {
  std::string file;
  int line = 0;
  std::size_t column = 1;
  std::string message;
  /// "file:line:col: message"
  std::string to_string() const;
};

struct Script {
  std::vector<ScriptStep> steps;
  std::vector<ScriptError> errors;  ///< every bad line, in order
};

/// Parses a whole script; `file` names it in errors.
Script parse_operator_script(std::string_view text, std::string file,
                             const proto::Profile& profile = proto::default_profile());

/// How one action ended (of either dialect's vocabulary).
template <class Action>
struct BasicActionResult {
  Action action;
  Time started{0};
  Time finished{0};
  bool ok = false;
  /// For a success what came back ("logged in: device 8, id 1, STOP",
  /// "P=1.5 I=0.25 ..."), for a failure the reason.
  std::string detail;
};
using ActionResult = BasicActionResult<OperatorAction>;

struct RunnerOptions {
  /// A `connect` that has not logged in this long after it was given fails.
  Duration connect_timeout = link::seconds(10);
  /// A `wait-data` without DATA this long fails.
  Duration data_timeout = link::seconds(5);
};

/// Carries out actions one at a time on a session. The session's event
/// sink must pass every event to `on_event`.
class OperatorRunner {
 public:
  using Done = std::function<void(const ActionResult&)>;

  OperatorRunner(link::Executor& executor, Wr8Session& session, RunnerOptions options = {});
  ~OperatorRunner();
  OperatorRunner(const OperatorRunner&) = delete;
  OperatorRunner& operator=(const OperatorRunner&) = delete;

  /// Feed every session event here (from the session's sink).
  void on_event(Time now, const Event& event);

  /// Starts `action`; `done` is called once when it ends (maybe at once).
  /// Programmer error (std::logic_error) while another action runs.
  void execute(OperatorAction action, Done done);

  /// Runs `actions` in order, each result to `each`; stops after the first
  /// failure unless `keep_going`. `finished(all_ok)` comes at the end.
  void run(std::vector<OperatorAction> actions, bool keep_going, Done each,
           std::function<void(bool all_ok)> finished);

  bool busy() const { return current_.has_value(); }

 private:
  struct Current {
    OperatorAction action;
    Time started{0};
    Done done;
    std::optional<std::uint8_t> coi;  // the request being waited for
    bool request_started = false;
    std::optional<link::Executor::TimerId> timer;
    std::vector<proto::Setting> settings;  // what get-settings returned
  };

  void start_request(SubmitResult submitted);
  void finish(bool ok, std::string detail);
  void arm_timer(Duration after, std::function<void()> fire);
  void on_request(const RequestEvent& r);
  void run_next();

  link::Executor& executor_;
  Wr8Session& session_;
  RunnerOptions options_;
  std::optional<Current> current_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);

  // The sequence `run` works through.
  std::vector<OperatorAction> queue_;
  std::size_t next_ = 0;
  bool keep_going_ = false;
  bool all_ok_ = true;
  Done each_;
  std::function<void(bool)> finished_;
};

/// "P=1.5 I=0.25 D=0.05 servo-zero=90" in the profile's presentation.
std::string format_settings(const std::vector<proto::Setting>& settings,
                            const proto::Profile& profile = proto::default_profile());

/// "250ms" / "1.5s" style text of a duration.
std::string format_duration(Duration d);

}  // namespace hil::client::wr8
