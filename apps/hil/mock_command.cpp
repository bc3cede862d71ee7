// hil mock: standalone mock cars for the desk, in real time, until Ctrl-C.

#include <unistd.h>
#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>

#include <csignal>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>

#include "apps/hil/cli_common.hpp"
#include "apps/hil/mock_desk.hpp"
#include "apps/hil/mock_options.hpp"
#include "harness/atomic_file.hpp"
#include "link/asio_executor.hpp"
#include "mocks/car.hpp"
#include "mocks/server.hpp"
#include "view/live_model.hpp"
#include "view/server.hpp"

namespace hil::apps {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// "/tmp/hil-arduino0" -> "/tmp/hil-arduino1" for car 1; a path that does not
// end in a number gets "-<index>" appended.
std::string nth_path(const std::string& first, std::size_t index) {
  if (index == 0) return first;
  std::size_t digits = first.size();
  while (digits > 0 && std::isdigit(static_cast<unsigned char>(first[digits - 1])) != 0)
    --digits;
  if (digits == first.size()) return first + "-" + std::to_string(index);
  return first.substr(0, digits) + std::to_string(std::stoull(first.substr(digits)) + index);
}

// "tcp://127.0.0.1:9000" -> 9000; 0 when there is no port.
unsigned port_of(const std::string& address) {
  const auto colon = address.rfind(':');
  if (colon == std::string::npos) return 0;
  try {
    return static_cast<unsigned>(std::stoul(address.substr(colon + 1)));
  } catch (const std::exception&) {
    return 0;
  }
}

/// The wall clock's time since local midnight: a real WR8 vehicle program
/// stamps its DATA with it.
link::Duration local_time_of_day() {
  using namespace std::chrono;
  const auto wall = system_clock::now();
  const std::time_t seconds_now = system_clock::to_time_t(wall);
  std::tm local{};
  localtime_r(&seconds_now, &local);
  return duration_cast<link::Duration>(hours(local.tm_hour) + minutes(local.tm_min) +
                                       seconds(local.tm_sec) +
                                       (wall - system_clock::from_time_t(seconds_now)));
}

link::Endpoint endpoint_for(const MockListenArgs& args, const MockPlan& plan, std::size_t index) {
  link::Endpoint e = mocks::default_endpoint(plan.kind, index, plan.profile);
  if (auto* tcp = std::get_if<link::TcpEndpoint>(&e)) {
    tcp->host = args.bind;
    if (args.port) {
      tcp->port = *args.port == 0 ? 0 : static_cast<std::uint16_t>(*args.port + index);
    }
  } else if (auto* pty = std::get_if<link::PtyEndpoint>(&e)) {
    if (!args.pty.empty()) pty->path = nth_path(args.pty, index);
    if (args.baud) pty->baud = *args.baud;
    pty->reset_on_open = link::milliseconds(args.reset_ms);
    if (plan.rfc2217) {
      // The same line, served by an RFC 2217 server instead of a pty.
      link::Rfc2217Endpoint served = *plan.rfc2217;
      if (served.port != 0) served.port = static_cast<std::uint16_t>(served.port + index);
      served.baud = pty->baud;
      served.reset_on_open = pty->reset_on_open;
      return served;
    }
  }
  return e;
}

std::string how_to_connect(const link::Endpoint& listening, const std::string& address) {
  if (const auto* pty = std::get_if<link::PtyEndpoint>(&listening)) {
    std::string text = "open " + pty->path + " as a serial port";
    if (pty->baud != 0) text += " at " + std::to_string(pty->baud) + " baud";
    return text;
  }
  if (const auto* served = std::get_if<link::Rfc2217Endpoint>(&listening)) {
    // What a client opens: the URI without hil's options (pySerial takes
    // rfc2217://HOST:PORT as it is).
    std::string text = "connect an RFC 2217 client to " + address.substr(0, address.find('?'));
    if (served->baud != 0) text += " (the line at " + std::to_string(served->baud) + " baud)";
    return text;
  }
  return "connect to " + address;
}

// The cars of one `hil mock`, the desk around them and the io_context they
// all run on, until SIGINT or SIGTERM.
class MockDesk {
 public:
  MockDesk(const MockArgs& args, MockPlan plan)
      : args_(args),
        plan_(std::move(plan)),
        status_(!args.desk.no_status && ::isatty(STDOUT_FILENO) != 0) {
    constexpr link::Duration kDay = std::chrono::hours(24);
    plan_.base.configs.svgui.time_of_day_at_start =
        ((local_time_of_day() - executor_.now()) % kDay + kDay) % kDay;
    // What a listener's clients cannot see (an RFC 2217 client's refused
    // connection, its bad input, a line set unlike the car's).
    if (!args.desk.quiet) context_.log = [this](const std::string& line) { log(line); };
  }

  void start_cars();
  void start_view();
  void start_console();
  void run();

 private:
  void log(const std::string& line) { status_.log(line); }
  RunningCar start_car(std::size_t i);
  void list_car(std::size_t i, const RunningCar& running, const link::Endpoint& listening);
  void write_ports_file();
  void redraw();
  void stop();

  const MockArgs& args_;
  MockPlan plan_;
  asio::io_context io_;
  // Caught from here on: a Ctrl-C while a big fleet starts is held until the
  // cars run and then stops them cleanly, instead of killing the process.
  asio::signal_set signals_{io_, SIGINT, SIGTERM};
  link::AsioExecutor executor_{io_};
  link::TransportContext context_{executor_, &io_};
  StatusLine status_;
  std::vector<RunningCar> cars_;
  std::vector<std::shared_ptr<view::WireWatch>> watches_;
  // After the cars: destroyed first, so the page never outlives them.
  std::unique_ptr<view::LiveModel> view_model_;
  std::unique_ptr<view::LiveViewServer> view_server_;
  std::unique_ptr<DeskConsole> console_;
};

RunningCar MockDesk::start_car(std::size_t i) {
  mocks::CarOptions options = plan_.base;
  options.name = "car" + std::to_string(i);
  options.seed = mocks::car_seed(plan_.seed, i);
  // Switched on one after another across a STAT period: a fleet's
  // telemetry and control ticks spread out instead of all cars waking in
  // the same instant, which would hold up every answer behind a burst of
  // N cars' work (docs/performance.md, the fleet).
  const auto& logi_config = options.configs.logi;
  options.configs.logi.boot_offset = logi_config.stat_period * static_cast<std::int64_t>(i) /
                                     static_cast<std::int64_t>(args_.count);
  if (!args_.desk.quiet) {
    options.configs.wr8.log = [this, name = options.name](const std::string& l) {
      log(name + ": " + l);
    };
    options.configs.svgui.log = options.configs.wr8.log;
    if (options.replay) options.replay->log = options.configs.wr8.log;
    if (options.configs.avr) options.configs.avr->log = options.configs.wr8.log;
  }
  RunningCar running;
  try {
    running.car = std::make_unique<mocks::MockCar>(std::move(options));
  } catch (const std::exception& e) {
    throw MockStartError{std::string("cannot build the car: ") + e.what(), 1};
  }
  for (const auto& b : plan_.behaviours)
    running.car->firmware().arm(b);
  mocks::ServerOptions server;
  server.listen = endpoint_for(args_.listen, plan_, i);
  server.faults = plan_.faults;
  server.seed = mocks::car_seed(plan_.seed, i);
  server.wire_log_path = args_.desk.wire_log;
  server.name = running.car->name();
  if (!args_.desk.quiet) server.log = [this](const std::string& line) { log(line); };
  if (args_.desk.view) {
    watches_.push_back(std::make_shared<view::WireWatch>(running.car->firmware().adapter()));
    server.observers.push_back(watches_.back());
  }
  running.server =
      std::make_unique<mocks::MockServer>(context_, running.car->firmware(), std::move(server));
  const auto listening = endpoint_for(args_.listen, plan_, i);
  try {
    running.server->start();
  } catch (const std::exception& e) {
    std::string message = "cannot listen on " + link::to_uri(listening) + ": " + e.what();
    if (std::holds_alternative<link::TcpEndpoint>(listening))
      message += " (is another hil mock running? choose another --port)";
    if (std::holds_alternative<link::Rfc2217Endpoint>(listening))
      message += " (is another hil mock running? choose another --rfc2217 port)";
    throw MockStartError{message, 1};
  }
  list_car(i, running, listening);
  return running;
}

// One line per car up to kCarsListed (every serial car: its path is what a
// user opens); beyond, the first, a summary and the last.
void MockDesk::list_car(std::size_t i, const RunningCar& running, const link::Endpoint& listening) {
  const bool list_each = args_.desk.verbose || args_.count <= kCarsListed || plan_.serial;
  if (!list_each && i != 0 && i + 1 != args_.count) return;
  const std::string& car = args_.car.kind;
  if (!list_each && i + 1 == args_.count) {
    const unsigned second = port_of(cars_.at(1).server->address());
    const unsigned last_but_one = port_of(cars_.back().server->address());
    std::cout << "hil mock " << car << ": ... " << args_.count - 2 << " more cars";
    if (args_.listen.port && *args_.listen.port != 0)
      std::cout << " on ports " << second << ".." << last_but_one << " (car N on "
                << *args_.listen.port << "+N)";
    else
      std::cout << " on free ports";
    std::cout << "; -v lists each, --ports-file writes them to a file\n";
  }
  std::cout << "hil mock " << car << ": " << running.car->name() << " "
            << how_to_connect(listening, running.server->address()) << '\n';
}

void MockDesk::start_cars() {
  cars_.reserve(args_.count);
  for (std::size_t i = 0; i < args_.count; ++i)
    cars_.push_back(start_car(i));
  if (!args_.desk.ports_file.empty()) write_ports_file();
  const std::string& bind = args_.listen.bind;
  if (!is_loopback(bind) && !plan_.serial)
    std::cerr << "warning: listening on " << bind << ", reachable from other machines\n";
  if (plan_.rfc2217 && !is_loopback(plan_.rfc2217->host)) {
    std::cerr << "warning: RFC 2217 server listening on " << plan_.rfc2217->host
              << ", reachable from other machines (anyone who connects drives the car)\n";
  }
  const std::string& world = args_.car.world;
  std::cout << "world " << (world.empty() ? "built-in warehouse" : world) << ", "
            << plan_.faults.rules.size() << " fault rule(s), " << plan_.behaviours.size()
            << " behaviour(s), seed " << plan_.seed << " (replay with --seed " << plan_.seed
            << "); Ctrl-C stops" << std::endl;
  if (const auto& avr = plan_.base.configs.avr) {
    std::cout << "firmware " << avr->elf.string() << " on an emulated ATmega328P at 16 MHz, pins "
              << avr->pins.source << "; the board resets when the port opens" << std::endl;
  }
  if (const auto& replay = plan_.base.replay) {
    const auto* fw = dynamic_cast<const mocks::ReplayFirmware*>(&cars_.front().car->firmware());
    const auto& header = replay->capture->header;
    const std::size_t requests = fw ? fw->index().answers.size() : 0;
    std::cout << "replaying " << replay->path << " (" << header.probe_version << ", profile "
              << plan_.profile << ", " << requests << " recorded request"
              << (requests == 1 ? "" : "s") << "); requests with no recording: "
              << (replay->unmatched == mocks::Unmatched::mock
                      ? "the " + plan_.profile + " mock answers"
                      : std::string("left unanswered"))
              << std::endl;
  }
}

// "<name> <address>" per car, whole or not at all: a script waiting for
// the file never reads half a list.
void MockDesk::write_ports_file() {
  std::string text;
  for (const auto& c : cars_)
    text += c.car->name() + " " + c.server->address() + "\n";
  try {
    harness::write_file_atomically(args_.desk.ports_file, text);
  } catch (const std::exception&) {
    throw MockStartError{"cannot write --ports-file " + args_.desk.ports_file, 1};
  }
}

void MockDesk::start_view() {
  if (!args_.desk.view) return;
  std::vector<view::ViewedCar> viewed;
  const std::string& faults_file = args_.car.faults;
  const std::string faults_text = faults_file.empty() ? std::string() : read_text(faults_file);
  for (std::size_t i = 0; i < cars_.size(); ++i)
    viewed.push_back(view::ViewedCar{cars_[i].car.get(), cars_[i].server.get(), watches_[i],
                                     plan_.faults, faults_text});
  view_model_ = std::make_unique<view::LiveModel>(std::move(viewed));
  view::ViewOptions options;
  options.port = plan_.view_port;
  view_server_ = std::make_unique<view::LiveViewServer>(io_, executor_, *view_model_, options);
  try {
    view_server_->start();
  } catch (const std::exception& e) {
    throw MockStartError{std::string("--view: ") + e.what() + " (choose another port: --view PORT)",
                         1};
  }
  std::cout << "view: " << view_server_->url() << std::endl;
}

void MockDesk::start_console() {
  if (!DeskConsole::available(args_.desk.commands)) return;
  try {
    console_ =
        std::make_unique<DeskConsole>(io_, cars_, [this](const std::string& line) { log(line); });
  } catch (const std::system_error& e) {
    throw MockStartError{
        std::string("--commands needs stdin to be a terminal or a pipe: ") + e.what(), 2};
  }
  std::cout << "type 'help' for desk commands (a parcel in front of the car, fault, hangup, ...)"
            << std::endl;
  console_->start();
}

// The status line is redrawn five times a second while it is on.
void MockDesk::redraw() {
  if (!status_.enabled()) return;
  status_.show(status_text(cars_));
  executor_.call_after(link::milliseconds(200), [this] { redraw(); });
}

void MockDesk::stop() {
  status_.end();
  std::uint64_t served = 0;
  for (auto& c : cars_) {
    served += c.server->clients_served();
    c.server->close();
  }
  if (console_) console_->stop();
  if (view_server_) view_server_->stop();
  std::cout << "hil mock: stopping (" << served << " client(s) served)" << std::endl;
  executor_.call_after(link::milliseconds(100), [this] { io_.stop(); });
}

void MockDesk::run() {
  redraw();
  signals_.async_wait([this](const std::error_code& ec, int) {
    if (!ec) stop();
  });
  io_.run();
}

int run_mock(const MockArgs& args) {
  try {
    MockDesk desk(args, plan_mock(args));
    desk.start_cars();
    desk.start_view();
    desk.start_console();
    desk.run();
  } catch (const MockStartError& e) {
    std::cerr << "hil mock: " << e.message << '\n';
    return e.status;
  }
  return 0;
}

}  // namespace

void register_mock(CLI::App& app, std::function<int()>& run) {
  auto args = std::make_shared<MockArgs>();
  auto* cmd = app.add_subcommand(
      "mock", "Run mock cars on this machine for a client or UI to talk to (real time)");
  cmd->add_option("car", args->car.kind,
                  "Which car: logi, wr8 (TCP), arduino, leka (pty, or --rfc2217)")
      ->required()
      ->check(CLI::IsMember({"logi", "wr8", "arduino", "leka"}));
  cmd->add_option("--profile", args->car.profile,
                  "The car's profile, its dialect (hil profiles CAR lists them; default: the "
                  "car's default profile), e.g. arduino --profile readme plays the README's board");
  cmd->add_option(
      "--bind", args->listen.bind,
      "Address TCP cars listen on (default 127.0.0.1; 0.0.0.0 opens it to the network)");
  cmd->add_option("--port", args->listen.port,
                  "First TCP port (default 9000 for logi, 9100 for wr8; car N uses PORT+N; 0 picks "
                  "free ports)");
  cmd->add_option(
      "--pty", args->listen.pty,
      "Serial cars: symlink to the first pty (default /tmp/hil-<car>0; car N counts up)");
  cmd->add_option(
      "--rfc2217", args->listen.rfc2217,
      "Serial cars: serve the car's serial port over the network with RFC 2217 (Telnet "
      "COM-PORT-OPTION) on [ADDR:]PORT instead of a pty, for Windows COM port redirectors and "
      "pySerial's rfc2217:// (ADDR 127.0.0.1 by default; car N on PORT+N; 0 picks free ports; "
      "one client at a time; docs/rfc2217.md)");
  cmd->add_option("--baud", args->listen.baud,
                  "Serial cars: line rate (default 9600 for arduino, 115200 for leka; 0 unpaced)");
  cmd->add_option("--reply-latency", args->car.reply_latency,
                  "The firmware's processing time before each answer, e.g. 20ms; 0 answers in "
                  "the same instant (default: the profile's, `hil profiles`; a serial car's bytes "
                  "also take their time on the line at --baud)");
  cmd->add_option("--reset-ms", args->listen.reset_ms,
                  "Serial cars: bytes sent this long after opening the port are lost, as when an "
                  "Arduino resets (default 0)");
  cmd->add_option("--world", args->car.world, "World file (default: the built-in warehouse)");
  cmd->add_option("--faults", args->car.faults, "Fault profile (YAML, docs/faults.md)");
  cmd->add_option("--behaviours", args->car.behaviours,
                  "Scripted behaviours to arm at start (YAML, docs/mocks.md)");
  cmd->add_option("--seed", args->car.seed,
                  "Seed for sensor noise and faults (printed when chosen at random)");
  auto* replay_option = cmd->add_option(
      "--replay", args->car.replay,
      "Play a real car recorded by `hil conform probe` instead of the mock: each request gets "
      "the answer recorded for it (the same bytes, else the same kind) after the recorded "
      "latency, telemetry comes on the recorded schedule (docs/mocks.md, \"Replaying a recorded "
      "car\")");
  cmd->add_option("--unmatched", args->car.unmatched,
                  "With --replay, a request the capture has no recording for: mock (the "
                  "capture's profile's mock answers it, the default) or silent (no answer)")
      ->check(CLI::IsMember({"mock", "silent"}))
      ->needs(replay_option);
  auto* sketch_option = cmd->add_option(
      "--sketch", args->car.sketch,
      "Arduino: build this sketch (.ino; cached by content) and run it on an emulated "
      "ATmega328P wired to the simulated robot, instead of the behavioural mock "
      "(docs/firmware.md)");
  auto* elf_option = cmd->add_option(
      "--elf", args->car.elf,
      "Arduino: run this firmware image (an ELF for the ATmega328P) on the emulated board");
  sketch_option->excludes(elf_option);
  cmd->add_option("--board-startup", args->car.board_startup,
                  "With --sketch or --elf: the time from the port opening to the sketch's first "
                  "instruction (default 66ms: the ATmega328P's own start-up; the Uno's bootloader "
                  "is not emulated)");
  cmd->add_option("--pins", args->car.pins,
                  "With --sketch or --elf: the pin map (YAML; default: pins.yaml beside the "
                  "sketch, else the protocol document's wiring, docs/firmware.md)");
  cmd->add_option("--log", args->desk.wire_log,
                  "Write every byte of every connection to an NDJSON wire log");
  cmd->add_option("--count", args->count,
                  "Run N independent cars on consecutive ports or ptys (TCP cars up to " +
                      std::to_string(kMaxTcpCars) + ", serial cars up to " +
                      std::to_string(kMaxSerialCars) + ")")
      ->check(CLI::Range(std::size_t{1}, kMaxTcpCars));
  cmd->add_option("--ports-file", args->desk.ports_file,
                  "Write one line per car, its name and where it listens, once every car "
                  "listens (for scripts; with --port 0 the ports are not consecutive)");
  cmd->add_option("--auth", args->car.auth,
                  "WR8: the 10-character authentication string (a wrong one is refused "
                  "after 1 s, doubling per failure in a row up to 30 s; failures are logged "
                  "without the string); svgui profiles: the text an AUTH must end with "
                  "(default konnichiwa; a wrong one is left unanswered, the connection open)");
  cmd->add_option("--data-hz", args->car.data_hz,
                  "WR8: DATA packets per second (default 10; svgui-head: fixed, HIGH-FREQ "
                  "20 and LOW-FREQ 1 per second)")
      ->check(CLI::Range(0.1, 1000.0));
  cmd->add_flag("-q,--quiet", args->desk.quiet,
                "No line per connection, fault and WR8 login failure");
  cmd->add_flag("-v,--verbose", args->desk.verbose,
                "One line per car even with more than " + std::to_string(kCarsListed) +
                    " cars (else the first, the last and a summary)");
  cmd->add_flag("--commands", args->desk.commands,
                "Read desk commands from stdin even when it is not a terminal (they are read "
                "from a terminal anyway; type 'help')");
  auto* view_option =
      cmd->add_option("--view", args->desk.view_port,
                      "Serve a live view of the cars on http://127.0.0.1:PORT/ (default " +
                          std::to_string(kDefaultViewPort) +
                          "; 0 picks a free port): the arena, the car, its sensors, the wire, and "
                          "a panel for faults and behaviours (docs/live-view.md)")
          ->expected(0, 1);
  cmd->add_flag("--no-status", args->desk.no_status,
                "No status line (it is off anyway when not a terminal)");
  cmd->footer(
      "Examples:\n"
      "  hil mock logi                                 # LOGI car on tcp://127.0.0.1:9000\n"
      "  hil mock wr8 --count 3 --port 9100            # three WR8 vehicles on 9100..9102\n"
      "  hil mock logi --count 1000 -q                 # a fleet of LOGI cars on 9000..9999\n"
      "  hil mock arduino --pty /tmp/robot0            # open /tmp/robot0 at 9600 baud\n"
      "  hil mock arduino --rfc2217 4000               # rfc2217://127.0.0.1:4000 for COM port\n"
      "                                                # redirectors and pySerial\n"
      "  hil mock leka --rfc2217 0.0.0.0:4000          # the same, reachable from other machines\n"
      "  hil mock logi --faults scenarios/faults/sticky-packets.yaml --log wire.ndjson\n"
      "  hil mock logi --view                          # and watch it on http://127.0.0.1:8080/\n"
      "  hil mock logi --replay car.ndjson             # the car `hil conform probe` recorded\n"
      "  hil mock arduino --sketch robot/robot.ino     # your own sketch on an emulated board\n"
      "Stops cleanly on Ctrl-C (SIGINT) or SIGTERM.");
  cmd->callback([&run, args, view_option] {
    args->desk.view = view_option->count() > 0;
    run = [args] { return run_mock(*args); };
  });
}

}  // namespace hil::apps
