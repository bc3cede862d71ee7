#pragma once
// logi-client --stdin-actions: operator actions read from standard input as
// they arrive and run one at a time, with one result line each and the
// event lines of hil's external-client contract (docs/client-contract.md).

#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>

#include "apps/logi-client/batch.hpp"
#include "client/logi/core.hpp"
#include "client/logi/operator.hpp"

namespace hil::apps::logi_client {

/// The contract's event line for a session event, if it has one:
/// "event connection connected", "event command MV:FWD accepted",
/// "event stale", "event fresh", "event notice <text>",
/// "event parse_error <error>", "event movement enabled|disabled [reason]".
/// The connection states are named as hil's own reference client records
/// them (WaitingToReconnect is "reconnecting").
std::optional<std::string> contract_event_line(const logi::Event& event);

/// One line of standard input, read as an operator action.
struct ActionLine {
  /// The action to run; empty for a blank or comment line and on error.
  std::optional<logi::OperatorStep> step;
  /// The line without its comment and outer blanks (what a result names).
  std::string text;
  /// Why the line does not parse ("column 7: expected ..."); empty if it does.
  std::string error;
};
ActionLine parse_action_line(int number, std::string_view line);

/// Runs the actions of standard input against tcp://host:port until the
/// input ends (then an emergency stop if the car may be moving, and a
/// disconnect) or SIGINT/SIGTERM. Returns 0 after the end of input, also
/// when actions failed (each result said so), 130 when interrupted.
int run_stdin_actions(const BatchOptions& options, std::ostream& out, std::ostream& err);

}  // namespace hil::apps::logi_client
