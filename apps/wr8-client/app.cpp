#include "apps/wr8-client/app.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "apps/common/stdin_lines.hpp"
#include "apps/common/version.hpp"
#include "apps/wr8-client/console.hpp"
#include "link/endpoint.hpp"
#include "protocol/common/car_profile.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::apps::wr8_client {

namespace wr8 = client::wr8;

namespace {

constexpr std::uint16_t kDocumentPort = 9100;

/// The real-program version of --profile, or nullopt for document.
std::optional<wr8::svgui::Version> version_of(const AppOptions& options) {
  return wr8::svgui::version_of_profile(options.profile);
}

/// Parses every argument (or the script) with `parse_line` / `parse_script`;
/// nullopt after printing every bad one.
template <class Action, class ParseLine, class ParseScript>
std::optional<std::vector<Action>> parse_batch(const AppOptions& options, std::ostream& errors,
                                               ParseLine parse_line, ParseScript parse_script) {
  std::vector<Action> actions;
  if (!options.script.empty()) {
    const auto text = read_script_text(options.script, std::cin);
    if (!text) {
      errors << options.script << ": cannot open the script\n";
      return std::nullopt;
    }
    const auto script = parse_script(*text, options.script);
    for (const auto& e : script.errors)
      errors << e.to_string() << '\n';
    if (!script.errors.empty()) return std::nullopt;
    for (const auto& s : script.steps)
      actions.push_back(s.action);
    return actions;
  }
  bool ok = true;
  for (std::size_t i = 0; i < options.actions.size(); ++i) {
    const auto parsed = parse_line(options.actions[i]);
    if (parsed.error) {
      errors << "argument " << i + 1 << ":" << parsed.error->column << ": " << parsed.error->message
             << '\n';
      ok = false;
    } else if (parsed.action) {
      actions.push_back(*parsed.action);
    }
  }
  if (!ok) return std::nullopt;
  return actions;
}

/// The program's loop for one dialect's session, runner and console.
template <class Kit, class Config>
int run_with(const AppOptions& options, Config config, std::vector<typename Kit::Action> actions) {
  const bool interactive = options.actions.empty() && options.script.empty();
  const std::uint16_t port = effective_port(options);
  link::Endpoint endpoint;
  try {
    endpoint = link::parse_endpoint("tcp://" + options.host + ":" + std::to_string(port));
  } catch (const std::exception& e) {
    std::cerr << "wr8-client: bad --host/--port: " << e.what() << '\n';
    return kExitUsage;
  }

  ProgramLoop program;
  typename Kit::Runner* runner_ptr = nullptr;
  BasicConsole<Kit>* console_ptr = nullptr;
  typename Kit::Session session(program.context(), endpoint, std::move(config),
                                [&](link::Time now, const typename Kit::Event& e) {
                                  if (runner_ptr != nullptr) runner_ptr->on_event(now, e);
                                  if (console_ptr != nullptr) console_ptr->on_event(now, e);
                                });
  wr8::RunnerOptions runner_options;
  runner_options.connect_timeout =
      link::Duration(static_cast<link::Duration::rep>(options.connect_timeout_s * 1e9));
  typename Kit::Runner runner(program.executor(), session, runner_options);
  runner_ptr = &runner;

  ConsoleOptions console_options;
  console_options.interactive = interactive;
  console_options.prompt = interactive && ::isatty(STDIN_FILENO) != 0;
  console_options.print_data = options.data;
  console_options.keep_going = options.keep_going;
  console_options.log_path = options.log_path;
  // The loop ends once the close has reached the socket.
  BasicConsole<Kit> console(program.executor(), session, runner, std::cout, console_options,
                            [&](int code) { program.finish(code); });
  console_ptr = &console;

  program.on_stop_signal([&](int) { console.interrupt(); });

  StdinLines reader(program.io(), {.line = [&](std::string line) { console.line(std::move(line)); },
                                   .end =
                                       [&](std::string rest) {
                                         if (!rest.empty()) console.line(std::move(rest));
                                         console.end_of_input();
                                       },
                                   .more = [&] { return !console.exited(); }});
  if (interactive) {
    const std::string profile = options.profile.empty() ? "document" : options.profile;
    std::cout << "wr8-client: vehicle at " << options.host << ":" << port << " (profile " << profile
              << "); type 'help' for the commands, 'connect' to log in\n"
              << std::flush;
    console.start();
    reader.start();
  } else {
    console.run_batch(std::move(actions));
  }
  return program.run();
}

}  // namespace

ParsedArguments parse_arguments(int argc, const char* const* argv) {
  AppOptions o;
  CLI::App app{"wr8-client: drive the WR8 vehicle over TCP (actions, a script, or interactively)"};
  app.set_version_flag("--version", version_line("wr8-client"));
  app.add_option("--host", o.host, "The vehicle's address (default 127.0.0.1)");
  app.add_option("--port", o.port,
                 "The vehicle's TCP port (default 9100 for profile document, 5556 for "
                 "svgui-2019 and svgui-head)")
      ->check(CLI::Range(1, 65535));
  add_profile_option(app, o.profile, "wr8",
                     "The vehicle's dialect: document (the protocol PDF, the default), svgui-2019 "
                     "or svgui-head (the real smart_vehicle_gui programs)");
  app.add_option("--auth", o.auth,
                 "Profile document: the 10-character authentication string (default HIL-WR8-01)");
  add_log_and_script_options(app, o.log_path,
                             "Write the communication log here at exit: .txt, .csv or .ndjson",
                             o.script, "Run the actions of this file, one per line");
  app.add_flag("--data", o.data,
               "Batch: print DATA as it arrives (on a change of state, else once a second)");
  app.add_flag("--keep-going", o.keep_going,
               "Batch: run every action even after one failed (exit 1 at the end)");
  app.add_flag("--no-login-wait", o.no_login_wait,
               "svgui profiles: use the connection as soon as AUTH is sent, as the real v2019 "
               "GUI does (the real v2019 vehicle answers no login)");
  app.add_option("--connect-timeout", o.connect_timeout_s,
                 "Seconds a connect action may take to log in (default 10)")
      ->check(CLI::Range(0.001, 3600.0));
  app.add_option("actions", o.actions,
                 "Actions to run, one per argument: connect \"drive 30\" \"turn 10\" get-settings "
                 "(no actions and no script: interactive)");
  app.footer(
      "Actions of profile document: connect, disconnect, drive CM, turn DEG, task CODE "
      "[VALUE...],\n"
      "  get-settings, set NAME=VALUE... (p, i, d, servo-zero), wait 500ms|1s, wait-data.\n"
      "Actions of profile svgui-2019: connect, disconnect, forward CM, wheels DEG, signals,\n"
      "  settings p=P i=I d=D servo-zero=Z, wait DURATION, wait-data.\n"
      "Actions of profile svgui-head: connect, disconnect, control X Y, control off,\n"
      "  set NAME=VALUE... (steering-p ... backward-int), set-request, wait DURATION, wait-data.\n"
      "'#' starts a comment. Interactive only: state, log [N], history, save-log PATH, help, "
      "quit.\n"
      "Exit codes: 0 all went well, 1 an action failed, 2 bad usage or a script line that does\n"
      "  not parse (file:line:col), 130 interrupted.\n"
      "Examples:\n"
      "  wr8-client connect \"drive 30\" \"turn 10\" get-settings\n"
      "  wr8-client --port 9101 --script scenarios/clients/wr8-client/drive-and-turn.wr8\n"
      "  wr8-client --profile svgui-head connect set-request \"control 0 0.3\" \"wait 2s\" "
      "\"control off\"\n"
      "  wr8-client --log session.csv          # interactive\n");
  return parse_options<AppOptions>(
      app, argc, argv, o, [](const AppOptions& given) -> std::optional<std::string> {
        if (!given.script.empty() && !given.actions.empty())
          return "wr8-client: give either --script or actions, not both";
        if (given.no_login_wait && !version_of(given))
          return std::string(
              "wr8-client: --no-login-wait is for profiles svgui-2019 and svgui-head; the "
              "document vehicle drops everything before a login");
        if (!given.auth.empty() && version_of(given))
          return "wr8-client: --auth is for profile document; " + given.profile +
                 " always sends the real programs' \"konnichiwa\"";
        if (!given.auth.empty() && given.auth.size() != wr8::proto::kAuthTextBytes)
          return "wr8-client: --auth must be exactly " +
                 std::to_string(wr8::proto::kAuthTextBytes) + " characters, got " +
                 std::to_string(given.auth.size()) + " (\"" + given.auth + "\")";
        return std::nullopt;
      });
}

wr8::ClientConfig client_config(const AppOptions& options) {
  wr8::ClientConfig config;
  if (options.auth.size() == wr8::proto::kAuthTextBytes)
    std::copy(options.auth.begin(), options.auth.end(), config.profile.auth_text.begin());
  return config;
}

std::uint16_t effective_port(const AppOptions& options) {
  if (options.port != 0) return options.port;
  const auto& profile = protocol::find_car_profile("wr8", options.profile);
  return profile.tcp_port != 0 ? profile.tcp_port : kDocumentPort;
}

std::optional<std::vector<wr8::OperatorAction>> batch_actions(const AppOptions& options,
                                                              const wr8::proto::Profile& profile,
                                                              std::ostream& errors) {
  return parse_batch<wr8::OperatorAction>(
      options, errors,
      [&](std::string_view line) { return wr8::parse_operator_line(line, profile); },
      [&](std::string_view text, const std::string& file) {
        return wr8::parse_operator_script(text, file, profile);
      });
}

std::optional<std::vector<wr8::SvguiAction>> svgui_batch_actions(const AppOptions& options,
                                                                 wr8::svgui::Version version,
                                                                 std::ostream& errors) {
  return parse_batch<wr8::SvguiAction>(
      options, errors, [&](std::string_view line) { return wr8::parse_svgui_line(line, version); },
      [&](std::string_view text, const std::string& file) {
        return wr8::parse_svgui_script(text, file, version);
      });
}

int run(const AppOptions& options) {
  const bool interactive = options.actions.empty() && options.script.empty();
  if (const auto version = version_of(options)) {
    std::vector<wr8::SvguiAction> actions;
    if (!interactive) {
      auto parsed = svgui_batch_actions(options, *version, std::cerr);
      if (!parsed) return kExitUsage;
      actions = std::move(*parsed);
    }
    wr8::SvguiConfig config;
    config.version = *version;
    config.wait_for_login = !options.no_login_wait;
    return run_with<SvguiKit>(options, config, std::move(actions));
  }
  const wr8::ClientConfig config = client_config(options);
  std::vector<wr8::OperatorAction> actions;
  if (!interactive) {
    auto parsed = batch_actions(options, config.profile, std::cerr);
    if (!parsed) return kExitUsage;
    actions = std::move(*parsed);
  }
  return run_with<DocumentKit>(options, config, std::move(actions));
}

}  // namespace hil::apps::wr8_client
