#pragma once
// An external client program driven the way docs/client-contract.md says:
// started through the shell with the car's address in placeholders and in
// the environment, operator actions written to its stdin one a line, one
// result line expected back per action, optional event lines turned into
// the same client records the reference client writes, and stdin closed at
// the end of the run. Real time only (it needs the context's io_context).

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "harness/reference_client.hpp"
#include "harness/timeline_recorder.hpp"
#include "link/transport.hpp"

namespace hil::harness {

/// Values of the placeholders of an exec command, by name ("host", "port",
/// "endpoint", "pty", "actions", "scenario").
using Placeholders = std::map<std::string, std::string>;

/// The names an exec command may use, in braces.
const std::vector<std::string>& placeholder_names();

/// `command` with every {name} replaced by the shell-quoted value of
/// `values`; throws std::invalid_argument naming an unknown placeholder
/// (with its column) or one that has no value for this car ("{pty}" for a
/// TCP car).
std::string substitute_placeholders(std::string_view command, const Placeholders& values);

/// `text` quoted for /bin/sh so it stays one word whatever it holds.
std::string shell_quote(std::string_view text);

/// What a line the program printed is, by the contract.
struct ClientLine {
  enum class Kind : std::uint8_t { result, event, output };
  Kind kind = Kind::output;
  bool ok = false;                             ///< result: `ok` (true) or `fail`
  std::string reason;                          ///< result: text after "fail ...: " (or all of it)
  RecordKind record_kind{ClientKind::notice};  ///< event: the client record's kind
  nlohmann::json record_data;                  ///< event: its data
};
/// Reads one line of the program's stdout (without its line break).
ClientLine parse_client_line(std::string_view line);

struct ExecOptions {
  std::string command;       ///< placeholders already substituted
  Placeholders environment;  ///< set as HIL_<NAME> for the program
  Duration startup_timeout{std::chrono::seconds(10)};
};

/// Starts and talks to the program; `context` must be a real-time one.
std::unique_ptr<ScenarioClient> make_exec_client(link::TransportContext& context,
                                                    ExecOptions options, RunTimeline& timeline);

}  // namespace hil::harness
