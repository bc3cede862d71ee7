#pragma once
// leka-client: sends command groups to the Leka robot from the command line
// or a script, one line per group (docs/clients/leka-client.md).

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "apps/common/program.hpp"
#include "client/leka/comm_log.hpp"
#include "client/leka/core.hpp"
#include "client/leka/operator.hpp"
#include "link/endpoint.hpp"

namespace hil::apps::leka_client {

struct AppOptions {
  std::string port;  ///< a device path (/dev/ttyUSB0) or a hil endpoint (pty://, tcp://)
  unsigned baud = 115200;
  std::string log_path;  ///< written at exit; the format follows the extension
  std::string script;    ///< a script file, "-" for stdin
  std::vector<std::string> groups;
  bool dry_run = false;
  int info_timeout_ms = 200;
  int frame_bytes = 64;  ///< largest frame, and the most bytes sent per 10 ms
  std::string profile;   ///< the robot's profile; empty is the default (readme)
};

/// What the command line asks for, or the exit code when it asks for nothing
/// to run (--help: 0, bad usage: 2; the message is already printed).
using ParsedArguments = apps::ParsedArguments<AppOptions>;
ParsedArguments parse_arguments(int argc, const char* const* argv);

/// The client settings the options ask for.
client::leka::ClientConfig config_for(const AppOptions& options);

using apps::endpoint_for_port;

/// The log format for a file name: .txt, .csv or .ndjson; nullopt otherwise.
std::optional<client::leka::LogFormat> log_format_for(const std::string& path);

/// The groups of the arguments, or the script (read from `in` for "-"),
/// with every line that does not parse; a script that cannot be read is
/// one error at line 0.
client::leka::Script load_script(const AppOptions& options, std::istream& in);

/// The one line of output for a line's result, e.g.
/// "demo.leka:3: ok, 2 frames, 22 bytes; info name=leka firmware=1.0.0 buffer=128 state=ok".
std::string format_result(const std::string& source, const client::leka::LineResult& result,
                          const client::leka::OperatorLine& line);

/// What --dry-run prints: each line, then each of its frames in hex.
std::string dry_run_text(const client::leka::Script& script,
                         const client::leka::ClientConfig& config);

/// Runs the program. Returns the exit code (0; 1 a failed group, the port
/// gone or unopenable; 2 a script error; 130 on SIGINT or SIGTERM).
int run(const AppOptions& options);

}  // namespace hil::apps::leka_client
