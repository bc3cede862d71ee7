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

#include "client/common/operator_text.hpp"
#include "client/wr8/action_runner.hpp"
#include "client/wr8/session.hpp"
#include "link/executor.hpp"

namespace hil::client::wr8 {

namespace op {
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
}  // namespace op

using OperatorAction = std::variant<op::Connect, op::Disconnect, op::Drive, op::Turn, op::RawTask,
                                    op::GetSettings, op::SetSettings, op::Wait, op::WaitData>;

/// The action as a line the parser reads back ("drive 30", "set p=1.5").
std::string to_text(const OperatorAction& action,
                    const proto::Profile& profile = proto::default_profile());

using client::LineError;
/// One parsed line: an action, nothing (blank or `#` comment), or an error.
using ParsedLine = client::ParseResult<OperatorAction>;

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

struct Script {
  std::vector<ScriptStep> steps;
  std::vector<client::ScriptError> errors;  ///< every bad line, in order
};

/// A script's lines read by `parse_line` (the ParseResult of one line) into
/// `ScriptOf`, Script or its like for another vocabulary: each action with
/// its line number, each bad line an error in `file`.
template <class ScriptOf, class ParseLine>
ScriptOf parse_script_lines(std::string_view text, const std::string& file, ParseLine parse_line) {
  ScriptOf script;
  int number = 0;
  for (const std::string_view line : split_lines(text)) {
    ++number;
    auto parsed = parse_line(line);
    if (parsed.error) {
      script.errors.push_back(
          {file, static_cast<std::size_t>(number), parsed.error->column, parsed.error->message});
    } else if (parsed.action) {
      script.steps.push_back({number, std::move(*parsed.action)});
    }
  }
  return script;
}

/// Parses a whole script; `file` names it in errors.
Script parse_operator_script(std::string_view text, std::string file,
                             const proto::Profile& profile = proto::default_profile());

using ActionResult = BasicActionResult<OperatorAction>;

/// The request a document action waits for.
struct RequestWait {
  std::optional<std::uint8_t> coi;
  bool started = false;
  std::vector<proto::Setting> settings;  ///< what get-settings returned
};

/// Carries out actions one at a time on a session. The session's event
/// sink must pass every event to `on_event`.
class OperatorRunner final
    : public ActionRunner<OperatorRunner, Wr8Session, OperatorAction, RequestWait> {
 public:
  OperatorRunner(link::Executor& executor, Wr8Session& session, RunnerOptions options = {})
      : ActionRunner(executor, session, options) {}

  /// Feed every session event here (from the session's sink).
  void on_event(Time now, const Event& event);

  /// Starts `action`; `done` is called once when it ends (maybe at once).
  /// Programmer error (std::logic_error) while another action runs.
  void execute(OperatorAction action, Done done);

 private:
  void start_request(SubmitResult submitted);
  void on_request(const RequestEvent& r);
};

/// "P=1.5 I=0.25 D=0.05 servo-zero=90" in the profile's presentation.
std::string format_settings(const std::vector<proto::Setting>& settings,
                            const proto::Profile& profile = proto::default_profile());

}  // namespace hil::client::wr8
