// logi-client: the LOGI logistics car's reference upper computer. With a
// script or actions it runs them in batch mode; with --stdin-actions it
// runs actions as they arrive on stdin (hil's external-client contract);
// otherwise it opens the terminal UI.

#include <CLI/CLI.hpp>

#include <iostream>
#include <string>
#include <vector>

#include "apps/common/program.hpp"
#include "apps/common/version.hpp"
#include "apps/logi-client/batch.hpp"
#include "apps/logi-client/stdin_actions.hpp"
#include "apps/logi-client/tui.hpp"
#include "client/logi/operator.hpp"

int main(int argc, char** argv) {
  namespace lc = hil::apps::logi_client;
  CLI::App app{
      "logi-client: upper computer for the LOGI logistics car (batch mode and terminal UI)"};
  app.set_version_flag("--version", hil::apps::version_line("logi-client"));
  lc::BatchOptions options;
  std::string script;
  std::string connect_timeout = "10s";
  bool continue_on_error = false;
  bool stdin_actions = false;
  std::vector<std::string> actions;
  app.add_option("--host", options.host, "The car's address (default 127.0.0.1)");
  app.add_option("--port", options.port, "The car's TCP port (default 9000)");
  app.add_flag("--keepalive", options.keepalive,
               "Repeat the held direction's MV every 300 ms while it is held");
  hil::apps::add_log_and_script_options(
      app, options.log_path,
      "Write the communication log at exit (batch mode); format by extension: .txt, .csv, "
      ".ndjson",
      script, "Run the actions of this file, one per line ('-': stdin)");
  app.add_flag("--continue-on-error", continue_on_error,
               "Run every action even after one failed (the exit status is still 1)");
  app.add_option("--connect-timeout", connect_timeout,
                 "How long 'connect' waits for the car, e.g. 10s (default), 2.5s, 500ms");
  app.add_flag("--stdin-actions", stdin_actions,
               "Run actions as they arrive on stdin, one result line each, with 'event' lines; "
               "exit 0 when stdin ends (docs/client-contract.md)");
  app.add_option("actions", actions,
                 "Actions to run in batch mode, one per argument, e.g. connect \"speed 50\"");
  app.footer(
      "Actions: connect, disconnect, speed N, mode MAN|AUTO, press DIR, release, station N,\n"
      "         run, stop, estop, wait DURATION, confirm (docs/clients/logi-client.md)\n"
      "Exit status: 0 all actions succeeded (--stdin-actions: stdin ended), 1 an action failed,\n"
      "             2 bad usage or script, 130 interrupted (Ctrl-C or SIGTERM)\n"
      "Examples:\n"
      "  logi-client                                   # terminal UI, car on 127.0.0.1:9000\n"
      "  logi-client --port 9000 connect \"speed 50\" \"mode MAN\" \"press FWD\" \"wait 1s\" "
      "release\n"
      "  logi-client --script scenarios/clients/logi-client/manual-drive.txt --log run.csv\n"
      "  hil run scenarios/logi --client-exec \"logi-client --stdin-actions --host {host} "
      "--port {port}\"");
  if (const auto exit_code = hil::apps::parse_command_line(app, argc, argv)) return *exit_code;

  const auto timeout = hil::client::logi::parse_duration(connect_timeout);
  if (!timeout) {
    std::cerr << "logi-client: --connect-timeout " << connect_timeout
              << ": expected a duration with a unit (500ms, 10s, 1m)\n";
    return lc::kExitUsage;
  }
  options.runner.connect_timeout = *timeout;
  options.runner.continue_on_error = continue_on_error;
  if (!options.log_path.empty()) {
    if (const auto problem = lc::check_log_path(options.log_path)) {
      std::cerr << "logi-client: " << *problem << '\n';
      return lc::kExitUsage;
    }
  }

  if (stdin_actions) {
    if (!script.empty() || !actions.empty()) {
      std::cerr << "logi-client: --stdin-actions reads the actions from stdin; give no --script "
                   "and no actions with it\n";
      return lc::kExitUsage;
    }
    return lc::run_stdin_actions(options, std::cout, std::cerr);
  }
  if (script.empty() && actions.empty()) {
    lc::TuiOptions tui;
    tui.host = options.host;
    tui.port = options.port;
    tui.keepalive = options.keepalive;
    return lc::run_tui(tui);
  }
  if (!script.empty() && !actions.empty()) {
    std::cerr << "logi-client: give either --script or actions on the command line, not both\n";
    return lc::kExitUsage;
  }
  const auto loaded =
      script.empty() ? lc::load_script_arguments(actions) : lc::load_script_file(script);
  if (!loaded.ok()) {
    for (const auto& e : loaded.errors)
      std::cerr << e.to_string() << '\n';
    return lc::kExitUsage;
  }
  return lc::run_batch(options, loaded.steps, std::cout, std::cerr);
}
