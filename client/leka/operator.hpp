#pragma once
// The Leka operator language: one text line becomes one command group (or a
// wait), a script is a list of such lines, and a runner plays a script
// through a LekaSession, stopping at the first failure.

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "client/common/operator_text.hpp"
#include "client/leka/core.hpp"
#include "client/leka/session.hpp"
#include "link/executor.hpp"

namespace hil::client::leka {

/// An `info` inside a line: it goes out as its own frame, in its place in
/// the line, and the line waits for its answer.
struct InfoPart {
  std::size_t column = 0;
};
/// Consecutive non-info commands of a line, sent as one group.
using LinePart = std::variant<GroupBuilder, InfoPart>;

/// One line that does something: a group or a wait.
struct OperatorLine {
  enum class Kind : std::uint8_t { group, wait };
  Kind kind = Kind::group;
  std::vector<LinePart> parts;  ///< kind == group: in the order written
  Duration wait{0};             ///< kind == wait
  std::size_t commands = 0;     ///< commands in the line, infos included
};

/// Where a line is wrong: the 1-based column and what was expected, e.g.
/// "belt single: led must be 0..19, got 25".
using OperatorError = client::LineError;

/// Parses one line: a line (`action`), nothing (blank or a `#` comment), or
/// an error. Never throws on input.
client::ParseResult<OperatorLine> parse_operator_line(std::string_view text,
                                                      const proto::ValueLimits& limits = {});

/// One line of a script, with where it came from.
struct ScriptLine {
  std::size_t number = 0;  ///< 1-based line number in its source
  std::string text;
  OperatorLine line;
};

struct Script {
  std::string source;             ///< file name, "-" for stdin, "arg" for command-line groups
  std::vector<ScriptLine> lines;  ///< blank and comment lines left out
  std::vector<client::ScriptError> errors;  ///< every line that did not parse, in order
  bool ok() const { return errors.empty(); }
};

/// Parses a whole script; every wrong line is an error.
Script parse_script(std::string_view text, const std::string& source,
                    const proto::ValueLimits& limits = {});
/// Each string is one line (command-line groups); line numbers count them.
Script parse_lines(const std::vector<std::string>& lines, const std::string& source,
                   const proto::ValueLimits& limits = {});

/// The frames a line sends, exactly as the core splits them under `config`.
std::vector<Bytes> frames_of(const OperatorLine& line, const ClientConfig& config);

/// What became of one script line.
struct LineResult {
  std::size_t number = 0;
  std::string text;
  bool ok = true;
  std::string error;  ///< why it failed, for a person
  std::size_t frames = 0;
  std::size_t bytes = 0;
  std::vector<InfoReply> infos;  ///< the answers, in the order asked
  Time started{0};
  Time finished{0};  ///< last frame out and every info answered (or the wait over)
};

/// Plays a script through a session: each line's frames go out (paced by
/// the session), its infos must be answered within the session's
/// info_timeout, and a wait lasts exactly its duration. The next line starts
/// when the previous one is finished. Stops at the first failure.
class OperatorRunner {
 public:
  using LineCallback = std::function<void(const LineResult&)>;
  /// true when every line succeeded.
  using DoneCallback = std::function<void(bool ok)>;

  /// `executor` and `session` must outlive the runner; the session is open.
  OperatorRunner(link::Executor& executor, LekaSession& session);
  ~OperatorRunner();
  OperatorRunner(const OperatorRunner&) = delete;
  OperatorRunner& operator=(const OperatorRunner&) = delete;

  void run(Script script, LineCallback on_line, DoneCallback on_done);
  /// Stops without reporting further lines or calling on_done.
  void cancel();
  bool running() const { return running_; }

 private:
  void next();
  void start_group(const ScriptLine& line);
  void check_group();
  void finish(bool ok, std::string error = {});

  link::Executor& executor_;
  LekaSession& session_;
  Script script_;
  std::size_t index_ = 0;
  LineCallback on_line_;
  DoneCallback on_done_;
  bool running_ = false;
  LineResult current_;
  std::size_t infos_waiting_ = 0;
  link::Executor::TimerId timer_ = 0;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
  std::uint64_t generation_ = 0;  // callbacks of an earlier line are ignored
};

}  // namespace hil::client::leka
