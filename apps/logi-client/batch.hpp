#pragma once
// logi-client's batch mode: runs operator actions against a LOGI car under
// the real-time driver and prints one line per action and per telemetry
// change or warning.

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "apps/common/program.hpp"
#include "client/logi/core.hpp"
#include "client/logi/operator.hpp"
#include "client/logi/session.hpp"
#include "link/executor.hpp"

namespace hil::apps::logi_client {

namespace logi = hil::client::logi;

struct BatchOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 9000;
  bool keepalive = false;
  std::string log_path;  ///< communication log written at exit; empty: none
  logi::OperatorRunnerOptions runner;
};

/// Exit statuses of logi-client (a failed action is kExitActionFailed).
using apps::kExitInterrupted;
using apps::kExitOk;
using apps::kExitUsage;
inline constexpr int kExitActionFailed = kExitFailed;

/// The actions of a script file ("-": standard input) or of command-line
/// arguments (one action each; errors name them "<command line>:N:col").
/// Every line that does not parse is an error, "file:line:col: what was
/// wrong"; a script that cannot be read is one error at line 0.
struct LoadedScript {
  std::vector<logi::OperatorStep> steps;
  std::vector<client::ScriptError> errors;
  bool ok() const { return errors.empty(); }
};
LoadedScript load_script_file(const std::string& path);
LoadedScript load_script_arguments(const std::vector<std::string>& actions);

/// Whether the log can be written in a format chosen by the path's
/// extension (.txt, .csv, .ndjson); the error for a person if not.
std::optional<std::string> check_log_path(const std::string& path);
/// The log in the format of the path's extension; false with `error` set on failure.
bool write_log(const logi::CommLog& log, const std::string& path, std::string& error);

/// Turns results and session events into the lines a person reads; a
/// telemetry line only when a field an operator acts on changes (not the
/// sonar or wheel speeds, which change all the time).
class BatchReporter {
 public:
  /// "[  1.234 s] ok   speed 50" or "[  1.234 s] FAIL press FWD: <reason>".
  static std::string result_line(const logi::ActionResult& result);
  /// The line for an event, if it is worth one.
  std::optional<std::string> event_line(logi::Time now, const logi::Event& event);

 private:
  std::optional<logi::proto::Status> shown_;
};

/// "[  1.234 s]": the time stamp every line starts with.
std::string stamp(logi::Time at);

/// Runs the steps against tcp://host:port until they end, a failure stops
/// them, or SIGINT/SIGTERM; writes the log; returns the exit status.
int run_batch(const BatchOptions& options, std::vector<logi::OperatorStep> steps, std::ostream& out,
              std::ostream& err);

}  // namespace hil::apps::logi_client
