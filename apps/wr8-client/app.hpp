#pragma once
// wr8-client's command line and its run under the real-time driver: the
// options, the actions they name, and the program's main loop.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "apps/common/program.hpp"
#include "client/wr8/operator.hpp"
#include "client/wr8/svgui_operator.hpp"

namespace hil::apps::wr8_client {

struct AppOptions {
  std::string host = "127.0.0.1";
  /// 0: the profile's port (9100, hil's WR8 port, for document; 5556, the
  /// real programs' port, for svgui-2019 and svgui-head).
  std::uint16_t port = 0;
  /// The WR8 dialect: document (the protocol PDF), svgui-2019 or svgui-head
  /// (the real smart_vehicle_gui programs); empty is document.
  std::string profile;
  std::string auth;  ///< empty: the profile's default string (document only)
  std::string log_path;
  std::string script;
  bool data = false;
  bool keep_going = false;
  /// svgui profiles: use the connection once AUTH is out, without waiting
  /// for AUTH-REPLY (the real v2019 vehicle answers no login).
  bool no_login_wait = false;
  double connect_timeout_s = 10;
  std::vector<std::string> actions;  ///< one action per argument
};

/// The options, or nullopt: exit with `exit_code`.
using ParsedArguments = apps::ParsedArguments<AppOptions>;

/// Reads the command line; prints help or usage errors itself.
ParsedArguments parse_arguments(int argc, const char* const* argv);

/// The batch's actions from the arguments or the script; nullopt after
/// printing "file:line:col: message" for every bad line to `errors`.
std::optional<std::vector<client::wr8::OperatorAction>> batch_actions(
    const AppOptions& options, const client::wr8::proto::Profile& profile, std::ostream& errors);

/// The session's configuration from the options (the login string).
client::wr8::ClientConfig client_config(const AppOptions& options);

/// The port to connect to: --port, else the profile's.
std::uint16_t effective_port(const AppOptions& options);

/// The batch's actions for a real program's profile, as batch_actions.
std::optional<std::vector<client::wr8::SvguiAction>> svgui_batch_actions(
    const AppOptions& options, client::wr8::svgui::Version version, std::ostream& errors);

/// Runs the program; returns its exit code.
int run(const AppOptions& options);

}  // namespace hil::apps::wr8_client
