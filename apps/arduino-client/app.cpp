#include "apps/arduino-client/app.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>

#include <cmath>
#include <functional>
#include <iostream>
#include <string_view>
#include <utility>

#include "apps/common/log_file.hpp"
#include "apps/common/stdin_lines.hpp"
#include "apps/common/version.hpp"
#include "client/arduino/session.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::apps::arduino_client {

namespace arduino = client::arduino;

namespace {

void say(const std::string& text) {
  if (text.empty()) return;
  std::cout << text << '\n' << std::flush;
}

/// The interactive loop: lines from stdin, parsed and queued on the runner.
/// Reads through asio so the session keeps running while nothing is typed.
class Repl {
 public:
  Repl(asio::io_context& io, arduino::OperatorRunner& runner, bool interactive,
       std::function<void(int)> exit)
      : input_(io, {.line = [this](std::string line) { handle(std::move(line)); },
                    .end = [this](std::string rest) { ended(std::move(rest)); },
                    .more = [this] { return !runner_.halted(); }}),
        runner_(runner),
        interactive_(interactive),
        exit_(std::move(exit)) {}
  Repl(const Repl&) = delete;
  Repl& operator=(const Repl&) = delete;

  void start() {
    prompt();
    input_.start();
  }

  void stop() { input_.stop(); }

  /// The runner has nothing left to do.
  void on_idle() {
    if (runner_.quit_requested() || input_done_) {
      exit_(0);
      return;
    }
    prompt();
  }

 private:
  void prompt() {
    if (!interactive_ || prompted_) return;
    prompted_ = true;
    std::cout << "arduino> " << std::flush;
  }

  // End of input (Ctrl-D, the pipe closed) or stdin cannot be read: a last
  // line without a newline still counts.
  void ended(std::string rest) {
    input_done_ = true;
    if (!rest.empty()) handle(std::move(rest));
    if (runner_.idle()) on_idle();
  }

  void handle(std::string line) {
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r'))
      line.pop_back();
    prompted_ = false;
    const auto parsed = arduino::parse_operator_line(line);
    if (parsed.error) {
      warn("error: column " + std::to_string(parsed.error->column) + ": " + parsed.error->message);
    } else if (parsed.action) {
      runner_.add(*parsed.action);
      return;  // the runner says when it is idle again
    }
    if (runner_.idle() && !input_done_) prompt();
  }

  StdinLines input_;
  arduino::OperatorRunner& runner_;
  bool interactive_;
  std::function<void(int)> exit_;
  bool input_done_ = false;
  bool prompted_ = false;
};

std::string link_change_text(const arduino::LinkChanged& change, const std::string& port) {
  std::string text = "link " + std::string(arduino::link_name(change.to));
  if (change.from == arduino::ConnectionState::connecting &&
      change.to == arduino::ConnectionState::down) {
    return text + ": cannot open " + port + " (" + change.reason + ")";
  }
  if (!change.reason.empty() && change.to != arduino::ConnectionState::connected) {
    text += ": " + change.reason;
  }
  return text;
}

}  // namespace

ParsedArguments parse_arguments(int argc, const char* const* argv) {
  AppOptions o;
  CLI::App app{"arduino-client: steer the Arduino serial robot (raw tokens, a script, or a REPL)"};
  app.set_version_flag("--version", version_line("arduino-client"));
  add_serial_options(app, o.port, o.baud,
                     "Serial device (/dev/ttyUSB0, /tmp/hil-arduino0) or a hil endpoint "
                     "(pty://..., tcp://HOST:PORT)",
                     "Line rate of the serial port (default 9600)")
      ->required();
  app.add_option("--timeout", o.timeout_s,
                 "Seconds the first attempt waits for an answer; each retry doubles it "
                 "(default 0.6)")
      ->check(CLI::Range(0.001, 60.0));
  app.add_option("--retries", o.retries, "Retries after the first attempt (default 3)")
      ->check(CLI::Range(0, 10));
  add_log_and_script_options(app, o.log_path,
                             "Write the frame log here at exit: .txt, .csv, .json or .ndjson",
                             o.script, "Run the commands of this file, one per line");
  add_profile_option(app, o.profile, "arduino",
                     "The board's dialect: firmware (the real sketch) or readme (the README's "
                     "examples); the default is hil mock arduino's");
  app.add_flag("--keep-going", o.keep_going,
               "Tokens and scripts: run every command even after one failed (exit 1 at the end)");
  app.add_option("tokens", o.tokens,
                 "Commands to run once each, e.g. PING \"V 160\" M:20 STATUS (no tokens and no "
                 "script: the REPL)");
  app.footer(
      "Commands: PING STATUS V <0..255> M <cm> R <deg> S B I HELP (any case, 'V 160' or "
      "'V:160'),\n"
      "  history, save-log PATH, reconnect, wait 500ms|1s, quit/exit; '#' starts a comment.\n"
      "Exit codes: 0 all went well, 1 a command failed (NACK, timeout, link down), 2 bad usage\n"
      "  or a script line that does not parse, 130 interrupted.\n"
      "Examples:\n"
      "  arduino-client --port /dev/ttyUSB0\n"
      "  arduino-client --port /tmp/hil-arduino0 PING \"V 160\" \"M 20\" STATUS\n"
      "  arduino-client --port /tmp/hil-arduino0 --script square.txt --log run.csv\n");
  return parse_options<AppOptions>(app, argc, argv, o, [](const AppOptions& given) {
    return !given.script.empty() && !given.tokens.empty()
               ? std::optional<std::string>(
                     "arduino-client: give either --script or command tokens, not both")
               : std::nullopt;
  });
}

TokenCommands commands_from_tokens(const std::vector<std::string>& tokens) {
  TokenCommands out;
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const auto parsed = arduino::parse_operator_line(tokens[i]);
    if (parsed.error) {
      out.errors.push_back("argument " + std::to_string(i + 1) + " '" + tokens[i] + "', column " +
                           std::to_string(parsed.error->column) + ": " + parsed.error->message);
    } else if (parsed.action) {
      out.commands.push_back(*parsed.action);
    }
  }
  return out;
}

int run(const AppOptions& options) {
  // Everything is parsed before the port is touched: a typo costs nothing.
  std::vector<arduino::OperatorCommand> batch;
  const bool is_batch = !options.script.empty() || !options.tokens.empty();
  if (!options.script.empty()) {
    const auto script = arduino::load_script(options.script);
    for (const auto& e : script.errors)
      warn(e.to_string());
    if (!script.ok()) return 2;
    batch = script.commands();
  } else if (!options.tokens.empty()) {
    auto tokens = commands_from_tokens(options.tokens);
    for (const auto& e : tokens.errors)
      warn("arduino-client: " + e);
    if (!tokens.errors.empty()) return 2;
    batch = std::move(tokens.commands);
  }
  const auto endpoint = port_endpoint("arduino-client", options.port, options.baud);
  if (!endpoint) return kExitUsage;

  arduino::ClientConfig config;
  config.base_timeout =
      link::Duration(static_cast<link::Duration::rep>(std::llround(options.timeout_s * 1e9)));
  config.max_retries = options.retries;
  config.dialect = protocol::arduino::dialect_named(options.profile);

  ProgramLoop program;
  arduino::ArduinoSession session(program.context(), *endpoint, config);
  arduino::OperatorRunner runner(session, program.executor(),
                                 {.keep_going = options.keep_going || !is_batch});
  auto finish = [&](int code) { program.finish(code, /*at_once=*/true); };

  runner.set_event_handler([&](const arduino::Event& event) {
    const auto* change = std::get_if<arduino::LinkChanged>(&event);
    // OPENING and CLOSED are the program's own doing; the rest is news.
    if (change == nullptr || change->to == arduino::ConnectionState::connecting ||
        change->to == arduino::ConnectionState::disconnected) {
      return;
    }
    warn(link_change_text(*change, options.port));
  });
  runner.set_outcome_handler(
      [](const arduino::CommandOutcome& outcome) { say(arduino::describe_outcome(outcome)); });

  program.on_stop_signal([&](int) { finish(kExitInterrupted); });

  std::unique_ptr<Repl> repl;
  session.open();
  if (is_batch) {
    runner.set_idle_handler([&] { finish(runner.failures() == 0 ? 0 : 1); });
    runner.add(batch);
  } else {
    const bool interactive = ::isatty(STDIN_FILENO) != 0;
    repl = std::make_unique<Repl>(program.io(), runner, interactive, finish);
    runner.set_idle_handler([&] { repl->on_idle(); });
    repl->start();
  }
  program.run();  // returns at once when the run already finished

  if (repl) repl->stop();
  runner.set_idle_handler({});
  runner.set_outcome_handler({});
  session.close();
  if (!options.log_path.empty() && !save_log(session.log(), options.log_path))
    program.fail("arduino-client: cannot write the log to " + options.log_path);
  return program.exit_code();
}

}  // namespace hil::apps::arduino_client
