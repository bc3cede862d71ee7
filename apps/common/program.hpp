#pragma once
// What every client program does the same way around its own work: the
// command line's exit codes, the --port endpoint, reading a script, time
// stamps in its output, and ending on SIGINT or SIGTERM.

#include <csignal>
#include <functional>
#include <iostream>
#include <optional>
#include <string>

#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>

#include "link/endpoint.hpp"
#include "link/time.hpp"

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

/// The whole text of a script file, or of `standard_input` for "-";
/// nullopt (errno set) when the file cannot be read.
std::optional<std::string> read_script_text(const std::string& path, std::istream& standard_input);

/// "   1.234 s": seconds with three decimals, right-aligned in `width`.
std::string seconds_stamp(link::Time at, int width);

/// SIGINT and SIGTERM on the program's io_context.
class StopSignals {
 public:
  explicit StopSignals(asio::io_context& io) : signals_(io, SIGINT, SIGTERM) {}

  /// `handler(signal)` runs on the next of them (once; call again for the next).
  void on_next(std::function<void(int signal)> handler);
  /// No more signal handling; a pending wait ends without calling its handler.
  void cancel();

 private:
  asio::signal_set signals_;
};

}  // namespace hil::apps
