#pragma once
// What every client program does the same way around its own work: the
// command line's exit codes, the --port endpoint, reading a script, time
// stamps in its output, and the run itself: its loop, ending on SIGINT or
// SIGTERM, and its exit status.

#include <csignal>
#include <functional>
#include <initializer_list>
#include <iostream>
#include <optional>
#include <string>

#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>

#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "link/time.hpp"
#include "link/transport.hpp"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace hil::apps {

/// Exit statuses of the client programs.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;  ///< an action or command failed
inline constexpr int kExitUsage = 2;   ///< bad usage or a script error
inline constexpr int kExitInterrupted = 130;

/// Unblocks `signals` in the calling thread, and so in every thread it
/// starts afterwards: a program whose parent left its stop signals blocked
/// (a supervisor, a test harness, a shell script) would otherwise never see
/// Ctrl-C or SIGTERM. Call it before any thread starts.
void unblock_signals(std::initializer_list<int> signals);

/// --port (a device path or a hil endpoint) and --baud (0..4000000), as the
/// serial clients take them; the --port option, for what else it needs.
CLI::Option* add_serial_options(CLI::App& app, std::string& port, unsigned& baud,
                                const std::string& port_help, const std::string& baud_help);

/// --log (the communication log written at exit, its format by extension)
/// and --script (the file of lines to run).
void add_log_and_script_options(CLI::App& app, std::string& log_path, const std::string& log_help,
                                std::string& script, const std::string& script_help);

/// --profile NAME for one car: a name the profile registry does not know
/// for `car` is a usage error listing the valid ones
/// (protocol/common/car_profile.hpp).
CLI::Option* add_profile_option(CLI::App& app, std::string& profile, const std::string& car,
                                const std::string& help);

/// Parses the command line; when it ends the program (--help, --version or
/// a usage error, already printed) the exit status: 0 or kExitUsage.
std::optional<int> parse_command_line(CLI::App& app, int argc, const char* const* argv);

/// What a program's command line asks for: the options to run with, or the
/// exit status when it asks for nothing to run (--help: 0; bad usage: 2,
/// the message already printed).
template <class Options>
struct ParsedArguments {
  std::optional<Options> options;
  int exit_code = 0;
};

/// Parses the command line into `options` (the variables `app` writes);
/// `problem` then names what is wrong with them, if anything, for stderr.
template <class Options>
ParsedArguments<Options> parse_options(
    CLI::App& app, int argc, const char* const* argv, Options& options,
    const std::function<std::optional<std::string>(const Options&)>& problem = {}) {
  ParsedArguments<Options> out;
  if (const auto exit_code = parse_command_line(app, argc, argv)) {
    out.exit_code = *exit_code;
    return out;
  }
  if (problem) {
    if (const auto message = problem(options)) {
      std::cerr << *message << '\n' << std::flush;
      out.exit_code = kExitUsage;
      return out;
    }
  }
  out.options = std::move(options);
  return out;
}

/// The endpoint for --port: a URI is taken as it is (a pty:// without a baud
/// gets `baud`), anything else is a serial device path.
link::Endpoint endpoint_for_port(const std::string& port, unsigned baud);
/// endpoint_for_port(), or nullopt after telling stderr
/// "<program>: --port: <what is wrong>".
std::optional<link::Endpoint> port_endpoint(const std::string& program, const std::string& port,
                                            unsigned baud);

/// A line on stderr, flushed at once.
void warn(const std::string& text);

/// The whole text of a script file, or of `standard_input` for "-";
/// nullopt (errno set) when the file cannot be read.
std::optional<std::string> read_script_text(const std::string& path, std::istream& standard_input);

/// "   1.234 s": seconds with three decimals, right-aligned in `width`.
std::string seconds_stamp(link::Time at, int width);

/// "SIGINT", "SIGTERM", "SIGHUP": a stop signal's name, for a message.
std::string signal_name(int signal);

/// A client program's run in real time: the io_context with its executor
/// and transport context, the stop signals (SIGINT and SIGTERM unless told
/// otherwise), and the exit status run() returns.
class ProgramLoop {
 public:
  explicit ProgramLoop(std::initializer_list<int> stop_signals = {SIGINT, SIGTERM});
  ProgramLoop(const ProgramLoop&) = delete;
  ProgramLoop& operator=(const ProgramLoop&) = delete;

  asio::io_context& io() { return io_; }
  link::AsioExecutor& executor() { return executor_; }
  link::TransportContext& context() { return context_; }

  /// `handler(signal)` on every stop signal until stop().
  void on_stop_signal(std::function<void(int signal)> handler);
  /// Runs the loop until stop(); returns exit_code().
  int run();

  /// The status run() returns: 0 until set.
  int exit_code() const { return exit_code_; }
  void set_exit_code(int code) { exit_code_ = code; }
  /// Something at the end went wrong (a log that cannot be written): warn()
  /// `message`, and a run that went well exits with kExitFailed.
  void fail(const std::string& message);
  /// Ends the run with `code`, unless it was ended before (then false and
  /// the status stays): stop(), now or once the work already posted has run.
  bool finish(int code, bool at_once = false);
  bool finished() const { return finished_; }
  /// No more stop signals; the loop ends now (`at_once`) or once the work
  /// already posted has run (a close reaches its socket first).
  void stop(bool at_once = false);

 private:
  void wait_for_signal();

  asio::io_context io_;
  link::AsioExecutor executor_{io_};
  link::TransportContext context_{executor_, &io_};
  asio::signal_set signals_;
  std::function<void(int)> on_signal_;
  bool finished_ = false;
  bool stopped_ = false;
  int exit_code_ = kExitOk;
};

}  // namespace hil::apps
