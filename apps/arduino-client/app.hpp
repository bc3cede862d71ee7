#pragma once
// arduino-client: steer the Arduino serial robot from a terminal, a script or
// the command line (docs/clients/arduino-client.md).

#include <optional>
#include <string>
#include <vector>

#include "apps/common/program.hpp"
#include "client/arduino/operator.hpp"
#include "link/endpoint.hpp"

namespace hil::apps::arduino_client {

struct AppOptions {
  std::string port;  ///< a device path (/dev/ttyUSB0) or a hil endpoint (pty://, tcp://)
  unsigned baud = 9600;
  double timeout_s = 0.6;  ///< first attempt's timeout; each retry doubles it
  int retries = 3;
  std::string log_path;  ///< the frame log is written here at exit (format by extension)
  std::string script;
  bool keep_going = false;  ///< batch: run every command even after a failure
  /// The board's profile: "firmware" (the real sketch, the default) or "readme".
  std::string profile;
  std::vector<std::string> tokens;
};

/// What the command line asks for, or the exit code when it asks for nothing
/// to run (--help: 0, bad usage: 2; the message is already printed).
using ParsedArguments = apps::ParsedArguments<AppOptions>;
ParsedArguments parse_arguments(int argc, const char* const* argv);

using apps::endpoint_for_port;

/// The commands of the token arguments, one line each; an error names the
/// argument and the column.
struct TokenCommands {
  std::vector<client::arduino::OperatorCommand> commands;
  std::vector<std::string> errors;
};
TokenCommands commands_from_tokens(const std::vector<std::string>& tokens);

/// Runs the program: tokens or a script in batch, else the REPL on stdin.
/// Returns the exit code (0, 1 a failed command, 2 a script error, 130 on a signal).
int run(const AppOptions& options);

}  // namespace hil::apps::arduino_client
