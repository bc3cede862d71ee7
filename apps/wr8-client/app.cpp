#include "apps/wr8-client/app.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <asio/io_context.hpp>
#include <asio/post.hpp>
#include <iostream>

#include "apps/common/stdin_lines.hpp"
#include "apps/wr8-client/console.hpp"
#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"

namespace hil::apps::wr8_client {

namespace wr8 = client::wr8;

ParsedArguments parse_arguments(int argc, const char* const* argv) {
  AppOptions o;
  CLI::App app{"wr8-client: drive the WR8 vehicle over TCP (actions, a script, or interactively)"};
  app.add_option("--host", o.host, "The vehicle's address (default 127.0.0.1)");
  app.add_option("--port", o.port, "The vehicle's TCP port (default 9100)");
  app.add_option("--auth", o.auth, "The 10-character authentication string (default HIL-WR8-01)");
  add_log_and_script_options(app, o.log_path,
                             "Write the communication log here at exit: .txt, .csv or .ndjson",
                             o.script, "Run the actions of this file, one per line");
  app.add_flag("--data", o.data,
               "Batch: print DATA as it arrives (on a change of state, else once a second)");
  app.add_flag("--keep-going", o.keep_going,
               "Batch: run every action even after one failed (exit 1 at the end)");
  app.add_option("--connect-timeout", o.connect_timeout_s,
                 "Seconds a connect action may take to log in (default 10)")
      ->check(CLI::Range(0.001, 3600.0));
  app.add_option("actions", o.actions,
                 "Actions to run, one per argument: connect \"drive 30\" \"turn 10\" get-settings "
                 "(no actions and no script: interactive)");
  app.footer(
      "Actions: connect, disconnect, drive CM, turn DEG, task CODE [VALUE...], get-settings,\n"
      "  set NAME=VALUE... (p, i, d, servo-zero), wait 500ms|1s, wait-data; '#' starts a comment.\n"
      "Interactive only: state, log [N], history, save-log PATH, help, quit.\n"
      "Exit codes: 0 all went well, 1 an action failed, 2 bad usage or a script line that does\n"
      "  not parse (file:line:col), 130 interrupted.\n"
      "Examples:\n"
      "  wr8-client connect \"drive 30\" \"turn 10\" get-settings\n"
      "  wr8-client --port 9101 --script scenarios/clients/wr8-client/drive-and-turn.wr8\n"
      "  wr8-client --log session.csv          # interactive\n");
  return parse_options<AppOptions>(
      app, argc, argv, o, [](const AppOptions& given) -> std::optional<std::string> {
        if (!given.script.empty() && !given.actions.empty())
          return "wr8-client: give either --script or actions, not both";
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

std::optional<std::vector<wr8::OperatorAction>> batch_actions(const AppOptions& options,
                                                              const wr8::proto::Profile& profile,
                                                              std::ostream& errors) {
  std::vector<wr8::OperatorAction> actions;
  if (!options.script.empty()) {
    const auto text = read_script_text(options.script, std::cin);
    if (!text) {
      errors << options.script << ": cannot open the script\n";
      return std::nullopt;
    }
    const auto script = wr8::parse_operator_script(*text, options.script, profile);
    for (const auto& e : script.errors)
      errors << e.to_string() << '\n';
    if (!script.errors.empty()) return std::nullopt;
    for (const auto& s : script.steps)
      actions.push_back(s.action);
    return actions;
  }
  bool ok = true;
  for (std::size_t i = 0; i < options.actions.size(); ++i) {
    const auto parsed = wr8::parse_operator_line(options.actions[i], profile);
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

int run(const AppOptions& options) {
  const wr8::ClientConfig config = client_config(options);
  const bool interactive = options.actions.empty() && options.script.empty();
  std::vector<wr8::OperatorAction> actions;
  if (!interactive) {
    auto parsed = batch_actions(options, config.profile, std::cerr);
    if (!parsed) return kExitUsage;
    actions = std::move(*parsed);
  }

  link::Endpoint endpoint;
  try {
    endpoint = link::parse_endpoint("tcp://" + options.host + ":" + std::to_string(options.port));
  } catch (const std::exception& e) {
    std::cerr << "wr8-client: bad --host/--port: " << e.what() << '\n';
    return kExitUsage;
  }

  asio::io_context io;
  link::AsioExecutor executor(io);
  link::TransportContext context{executor, &io};

  wr8::OperatorRunner* runner_ptr = nullptr;
  Wr8Console* console_ptr = nullptr;
  wr8::Wr8Session session(context, endpoint, config, [&](link::Time now, const wr8::Event& e) {
    if (runner_ptr != nullptr) runner_ptr->on_event(now, e);
    if (console_ptr != nullptr) console_ptr->on_event(now, e);
  });
  wr8::RunnerOptions runner_options;
  runner_options.connect_timeout =
      link::Duration(static_cast<link::Duration::rep>(options.connect_timeout_s * 1e9));
  wr8::OperatorRunner runner(executor, session, runner_options);
  runner_ptr = &runner;

  int exit_code = kExitOk;
  ConsoleOptions console_options;
  console_options.interactive = interactive;
  console_options.prompt = interactive && ::isatty(STDIN_FILENO) != 0;
  console_options.print_data = options.data;
  console_options.keep_going = options.keep_going;
  console_options.log_path = options.log_path;
  Wr8Console console(executor, session, runner, std::cout, console_options, [&](int code) {
    exit_code = code;
    // Let the close reach the socket before the loop ends.
    asio::post(io, [&io] { io.stop(); });
  });
  console_ptr = &console;

  StopSignals signals(io);
  signals.on_next([&](int) { console.interrupt(); });

  StdinLines reader(io, {.line = [&](std::string line) { console.line(std::move(line)); },
                         .end =
                             [&](std::string rest) {
                               if (!rest.empty()) console.line(std::move(rest));
                               console.end_of_input();
                             },
                         .more = [&] { return !console.exited(); }});
  if (interactive) {
    std::cout << "wr8-client: vehicle at " << options.host << ":" << options.port
              << "; type 'help' for the commands, 'connect' to log in\n"
              << std::flush;
    console.start();
    reader.start();
  } else {
    console.run_batch(std::move(actions));
  }
  io.run();
  return exit_code;
}

}  // namespace hil::apps::wr8_client
