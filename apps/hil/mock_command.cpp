// hil mock: standalone mock cars for the desk, in real time, until Ctrl-C.

#include <sys/ioctl.h>
#include <sys/resource.h>
#include <unistd.h>
#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <asio/read_until.hpp>
#include <asio/signal_set.hpp>
#include <asio/streambuf.hpp>

#include <fcntl.h>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <numbers>
#include <random>
#include <sstream>

#include "apps/hil/cli_common.hpp"
#include "link/asio_executor.hpp"
#include "link/faults/profile_yaml.hpp"
#include "mocks/behaviour_yaml.hpp"
#include "mocks/car.hpp"
#include "mocks/server.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/common/car_profile.hpp"
#include "sim/arena_yaml.hpp"
#include "view/live_model.hpp"
#include "view/server.hpp"

namespace hil::apps {
namespace {

struct MockArgs {
  std::string car;
  std::string profile;  ///< empty: the car's default profile
  std::string bind = "127.0.0.1";
  std::optional<std::uint16_t> port;
  std::string pty;
  std::optional<unsigned> baud;
  std::string reply_latency;  ///< a duration; empty: none
  unsigned reset_ms = 0;
  std::string world;
  std::string faults;
  std::string behaviours;
  std::string wire_log;
  std::optional<std::uint64_t> seed;
  std::size_t count = 1;
  std::string auth;
  std::optional<double> data_hz;
  bool quiet = false;
  bool verbose = false;
  std::string ports_file;
  bool no_status = false;
  bool commands = false;
  bool view = false;
  std::string view_port;  ///< empty: the default port
};

constexpr std::uint16_t kDefaultViewPort = 8080;

// A fleet of TCP cars is what a fleet manager is tested against; one
// io_context serves 1,000 LOGI cars in real time on 2 cores
// (docs/performance.md), and each car holds two descriptors (its listener and
// its client), so 10,000 cars stay within common hard limits of 20,000+ and
// within the port range. Serial cars each hold a pty pair and a symlink in
// /tmp, and the kernel's pty pool is shared with every terminal on the
// machine, so they keep a smaller limit.
constexpr std::size_t kMaxTcpCars = 10000;
constexpr std::size_t kMaxSerialCars = 64;
// Up to this many cars, one line each; beyond, the first, the last and a
// summary (-v lists every car, --ports-file writes them to a file).
constexpr std::size_t kCarsListed = 16;
// Descriptors besides the cars': stdio, the status line, the view, a wire log.
constexpr rlim_t kSpareDescriptors = 64;

// "--view" alone, "--view 8081", "--view 0" (any free port).
std::optional<std::uint16_t> parse_view_port(const std::string& text) {
  if (text.empty()) return kDefaultViewPort;
  if (text.size() > 5 || text.find_first_not_of("0123456789") != std::string::npos)
    return std::nullopt;
  const unsigned long port = std::stoul(text);
  if (port > 65535) return std::nullopt;
  return static_cast<std::uint16_t>(port);
}

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

// Raises the soft limit on open descriptors to the hard one when the cars
// need more than the soft limit allows (the usual soft limit, 1,024, is
// about 500 TCP cars). Returns an error for the user when even the hard limit
// is too low.
std::optional<std::string> make_room_for_descriptors(std::size_t cars, bool serial) {
  const rlim_t needed = static_cast<rlim_t>(cars) * 2 + kSpareDescriptors;
  rlimit limit{};
  if (::getrlimit(RLIMIT_NOFILE, &limit) != 0) return std::nullopt;
  if (limit.rlim_cur != RLIM_INFINITY && limit.rlim_cur >= needed) return std::nullopt;
  if (limit.rlim_cur == RLIM_INFINITY) return std::nullopt;
  if (limit.rlim_max != RLIM_INFINITY && limit.rlim_max < needed) {
    return std::to_string(cars) + " cars need about " + std::to_string(needed) + " open files (" +
           (serial ? "a pty pair" : "a listening socket and a client") +
           " per car), but the hard limit is " + std::to_string(limit.rlim_max) +
           " (ulimit -Hn); run fewer cars or raise the hard limit (limits.conf, systemd's "
           "LimitNOFILE, or ulimit -Hn as root)";
  }
  const rlim_t old_soft = limit.rlim_cur;
  limit.rlim_cur = limit.rlim_max;
  if (::setrlimit(RLIMIT_NOFILE, &limit) != 0) {
    return "cannot raise the open-file limit from " + std::to_string(old_soft) + " to " +
           std::to_string(limit.rlim_max) + ": " + std::strerror(errno);
  }
  return std::nullopt;
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

// Writes "<name> <address>" per car, whole or not at all: a script waiting
// for the file never reads half a list.
bool write_ports_file(const std::string& path, const std::vector<std::string>& lines) {
  const std::string partial = path + ".partial";
  {
    std::ofstream out(partial, std::ios::trunc);
    for (const auto& line : lines)
      out << line << '\n';
    if (!out.flush()) return false;
  }
  std::error_code ec;
  std::filesystem::rename(partial, path, ec);
  return !ec;
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

link::Endpoint endpoint_for(const MockArgs& args, mocks::CarKind kind, std::size_t index) {
  link::Endpoint e = mocks::default_endpoint(kind, index, args.profile);
  if (auto* tcp = std::get_if<link::TcpEndpoint>(&e)) {
    tcp->host = args.bind;
    if (args.port) {
      tcp->port = *args.port == 0 ? 0 : static_cast<std::uint16_t>(*args.port + index);
    }
  } else if (auto* pty = std::get_if<link::PtyEndpoint>(&e)) {
    if (!args.pty.empty()) pty->path = nth_path(args.pty, index);
    if (args.baud) pty->baud = *args.baud;
    pty->reset_on_open = link::milliseconds(args.reset_ms);
  }
  return e;
}

std::string how_to_connect(const link::Endpoint& listening, const std::string& address) {
  if (const auto* pty = std::get_if<link::PtyEndpoint>(&listening)) {
    std::string text = "open " + pty->path + " as a serial port";
    if (pty->baud != 0) text += " at " + std::to_string(pty->baud) + " baud";
    return text;
  }
  return "connect to " + address;
}

// The terminal's status line: redrawn in place; log lines are printed above it.
class StatusLine {
 public:
  explicit StatusLine(bool enabled) : enabled_(enabled) {}
  void log(const std::string& line) {
    if (enabled_) std::cout << "\r\033[K";
    std::cout << line << '\n';
    if (enabled_) std::cout << last_;
    std::cout << std::flush;
  }
  void show(const std::string& text) {
    if (!enabled_) return;
    last_ = fit(text);
    std::cout << "\r\033[K" << text << std::flush;
  }
  void end() {
    if (enabled_ && !last_.empty()) std::cout << '\n' << std::flush;
    last_.clear();
    enabled_ = false;
  }
  bool enabled() const { return enabled_; }

 private:
  // A line longer than the terminal would wrap and break the redraw in place.
  static std::string fit(const std::string& text) {
    winsize w{};
    if (::ioctl(STDOUT_FILENO, TIOCGWINSZ, &w) != 0 || w.ws_col == 0) return text;
    std::string out;
    std::size_t columns = 0;
    for (const char c : text) {
      const bool starts_character = (static_cast<unsigned char>(c) & 0xC0) != 0x80;
      if (starts_character && ++columns >= w.ws_col) break;
      out += c;
    }
    return out;
  }

  bool enabled_;
  std::string last_;
};

struct RunningCar {
  std::unique_ptr<mocks::MockCar> car;
  std::unique_ptr<mocks::MockServer> server;
};

std::string status_text(const std::vector<RunningCar>& cars) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(2);
  std::uint64_t in = 0;
  std::uint64_t sent = 0;
  std::uint64_t bad = 0;
  std::uint64_t faults = 0;
  std::size_t clients = 0;
  for (const auto& c : cars) {
    const auto& s = c.car->firmware().stats();
    in += s.frames_in;
    sent += s.frames_out;
    bad += s.bad_frames;
    faults += c.server->faults_injected();
    if (c.server->client_connected()) ++clients;
  }
  if (cars.size() == 1) {
    auto& c = cars.front();
    const auto pose = c.car->vehicle().pose();
    out << c.car->name() << " x " << pose.x_m << " y " << pose.y_m << " hdg "
        << static_cast<int>(std::lround(pose.heading_rad * 180 / std::numbers::pi)) << "° | "
        << c.car->firmware().summary() << " | client "
        << (c.server->client_connected() ? "yes" : "no");
  } else {
    out << cars.size() << " cars | " << clients << " client(s)";
  }
  out << " | frames in " << in << " out " << sent << " bad " << bad << " | faults " << faults;
  return out.str();
}

// Desk commands typed while the cars run: drop a parcel in front of a car,
// take it away, fail the car, hang up on the client, pick the car up.
class DeskConsole {
 public:
  DeskConsole(asio::io_context& io, std::vector<RunningCar>& cars,
              std::function<void(const std::string&)> say)
      : stdin_flags_(::fcntl(STDIN_FILENO, F_GETFL)),
        input_(io, ::dup(STDIN_FILENO)),
        cars_(cars),
        say_(std::move(say)) {}
  ~DeskConsole() { stop(); }
  DeskConsole(const DeskConsole&) = delete;
  DeskConsole& operator=(const DeskConsole&) = delete;

  /// Whether desk commands can be read: stdin is a terminal this process
  /// owns (not a background job), or `forced` (a pipe, for scripts).
  static bool available(bool forced) {
    if (forced) return true;
    return ::isatty(STDIN_FILENO) != 0 && ::tcgetpgrp(STDIN_FILENO) == ::getpgrp();
  }

  void start() {
    // Sent to `hil mock` put in the background later: the read fails
    // instead of stopping the process, and the cars run on.
    std::signal(SIGTTIN, SIG_IGN);
    read();
  }
  void stop() {
    if (!input_.is_open()) return;
    std::error_code ec;
    input_.close(ec);
    // Asio made the shared file description non-blocking; the shell that
    // gets the terminal back expects it as it was.
    if (stdin_flags_ != -1) ::fcntl(STDIN_FILENO, F_SETFL, stdin_flags_);
  }

  static std::string help() {
    return "commands: obstacle [CM] (a parcel CM ahead of the car's front, default 15) | clear "
           "(take the parcels away) | fault | recover | hangup (close the client's connection) | "
           "place X Y [DEG] | car N (which car the commands act on) | help";
  }

 private:
  void read() {
    asio::async_read_until(input_, buffer_, '\n', [this](std::error_code ec, std::size_t n) {
      if (ec) return;  // stdin closed: the cars run on
      std::string line(asio::buffers_begin(buffer_.data()),
                       asio::buffers_begin(buffer_.data()) + static_cast<std::ptrdiff_t>(n));
      buffer_.consume(n);
      run(line);
      read();
    });
  }

  void run(const std::string& line) {
    std::istringstream in(line);
    std::string word;
    if (!(in >> word)) return;
    RunningCar& car = cars_.at(selected_);
    auto& firmware = car.car->firmware();
    auto& vehicle = car.car->vehicle();
    const std::string who = car.car->name();
    if (word == "help") {
      say_(help());
    } else if (word == "obstacle") {
      double cm = 15;
      if (!(in >> cm)) cm = 15;
      if (cm < 0 || cm > 400) {
        say_("obstacle: CM must be 0..400");
        return;
      }
      const auto footprint = vehicle.chassis().footprint();
      const double front_m = footprint.center_ahead_m + footprint.length_m / 2;
      const double depth_m = 0.10;
      const auto center = vehicle.pose().to_arena({front_m + cm / 100 + depth_m / 2, 0});
      const auto index = car.car->world().add_obstacle(
          sim::BoxObstacle{"parcel", center, depth_m, 0.30, vehicle.pose().heading_rad});
      parcels_[selected_].push_back(index);
      say_(who + ": parcel dropped " + std::to_string(static_cast<int>(cm)) + " cm ahead");
    } else if (word == "clear") {
      std::size_t lifted = 0;
      for (const auto index : parcels_[selected_])
        if (car.car->world().remove_obstacle(index)) ++lifted;
      parcels_[selected_].clear();
      say_(who + ": " + std::to_string(lifted) + " parcel(s) taken away");
    } else if (word == "fault") {
      firmware.arm(mocks::Behaviour{"desk fault", {}, mocks::EnterFault{}});
      say_(who + ": fault state");
    } else if (word == "recover") {
      firmware.arm(mocks::Behaviour{"desk recover", {}, mocks::ClearFault{}});
      say_(who + ": fault cleared");
    } else if (word == "hangup") {
      firmware.arm(mocks::Behaviour{"desk hangup", {}, mocks::CloseConnection{}});
      say_(who + (firmware.connected() ? ": closing the client's connection" : ": no client"));
    } else if (word == "place") {
      double x = 0;
      double y = 0;
      double deg = 0;
      if (!(in >> x >> y)) {
        say_("place: give X Y in metres and optionally a heading in degrees");
        return;
      }
      in >> deg;
      vehicle.place(sim::Pose{x, y, deg * std::numbers::pi / 180});
      say_(who + ": placed");
    } else if (word == "car") {
      std::size_t n = 0;
      if (!(in >> n) || n >= cars_.size()) {
        say_("car: give a number from 0 to " + std::to_string(cars_.size() - 1));
        return;
      }
      selected_ = n;
      say_("commands now act on " + cars_.at(n).car->name());
    } else {
      say_("unknown command '" + word + "' (" + help() + ")");
    }
  }

  int stdin_flags_;
  asio::posix::stream_descriptor input_;
  asio::streambuf buffer_;
  std::vector<RunningCar>& cars_;
  std::function<void(const std::string&)> say_;
  std::size_t selected_ = 0;
  std::map<std::size_t, std::vector<std::size_t>> parcels_;
};

int run_mock(const MockArgs& args) {
  const auto kind = mocks::parse_car_kind(args.car);
  mocks::CarOptions base;
  base.kind = *kind;
  // A mock on a shared machine is a target for guessing the login: each
  // failure in a row doubles the refusal delay up to 30 s. Scenarios keep
  // the library's constant 1 s, which their timings rely on.
  base.configs.wr8.wrong_auth_max_delay = link::seconds(30);
  link::FaultProfile faults;
  std::vector<mocks::Behaviour> behaviours;
  try {
    if (!args.world.empty()) base.arena = sim::load_arena(args.world);
    if (!args.faults.empty()) faults = link::load_fault_profile(args.faults);
    if (!args.behaviours.empty()) behaviours = mocks::load_behaviours(args.behaviours);
  } catch (const std::exception& e) {
    std::cerr << "hil mock: " << e.what() << '\n';
    return 1;
  }
  try {
    mocks::apply_profile(base.configs, *kind, args.profile);
  } catch (const protocol::ProfileError& e) {
    std::cerr << "hil mock: --profile: " << e.what() << '\n';
    return 2;
  }
  if (!args.auth.empty()) {
    if (args.auth.size() != protocol::wr8::kAuthTextBytes) {
      std::cerr << "hil mock: --auth must be exactly " << protocol::wr8::kAuthTextBytes
                << " characters, got " << args.auth.size() << " (\"" << args.auth << "\")\n";
      return 2;
    }
    std::copy(args.auth.begin(), args.auth.end(), base.configs.wr8.profile.auth_text.begin());
    base.configs.svgui.auth_suffix = args.auth;
  }
  if (!args.reply_latency.empty()) {
    const auto latency = link::parse_duration(args.reply_latency);
    if (!latency) {
      std::cerr << "hil mock: --reply-latency must be a duration with a unit (20ms, 1.5s), got '"
                << args.reply_latency << "'\n";
      return 2;
    }
    base.configs.reply_latency = *latency;
  }
  if (args.data_hz) {
    if (base.configs.svgui.version == protocol::wr8::svgui::Version::head) {
      std::cerr << "hil mock: --data-hz: the svgui-head vehicle sends HIGH-FREQ DATA every 50 ms "
                   "and LOW-FREQ every 1000 ms, as the real program does\n";
      return 2;
    }
    const auto period = std::chrono::duration_cast<link::Duration>(
        std::chrono::duration<double>(1.0 / *args.data_hz));
    base.configs.wr8.data_period = period;
    base.configs.svgui.v2019_data_period = period;
  }
  const bool serial = std::holds_alternative<link::PtyEndpoint>(mocks::default_endpoint(*kind, 0));
  if (serial && args.count > kMaxSerialCars) {
    std::cerr << "hil mock: --count for serial cars is at most " << kMaxSerialCars
              << " (each holds a pty from the pool every terminal shares), got " << args.count
              << '\n';
    return 2;
  }
  if (!serial && args.port && *args.port != 0 && *args.port + args.count - 1 > 65535) {
    std::cerr << "hil mock: --port " << *args.port << " with --count " << args.count
              << " runs past port 65535 (car N listens on PORT+N); choose a lower --port or "
                 "--port 0\n";
    return 2;
  }
  if (const auto problem = make_room_for_descriptors(args.count, serial)) {
    std::cerr << "hil mock: " << *problem << '\n';
    return 1;
  }
  const std::uint64_t seed = args.seed ? *args.seed : std::random_device{}();
  const auto view_port = parse_view_port(args.view_port);
  if (args.view && !view_port) {
    std::cerr << "hil mock: --view takes a port number 0..65535 (0: any free port), got \""
              << args.view_port << "\"\n";
    return 2;
  }

  asio::io_context io;
  // Caught from here on: a Ctrl-C while a big fleet starts is held until the
  // cars run and then stops them cleanly, instead of killing the process.
  asio::signal_set signals(io, SIGINT, SIGTERM);
  link::AsioExecutor executor(io);
  {
    constexpr link::Duration kDay = std::chrono::hours(24);
    base.configs.svgui.time_of_day_at_start =
        ((local_time_of_day() - executor.now()) % kDay + kDay) % kDay;
  }
  link::TransportContext context{executor, &io};
  StatusLine status(!args.no_status && ::isatty(STDOUT_FILENO) != 0);
  const auto log = [&status](const std::string& line) { status.log(line); };

  std::vector<RunningCar> cars;
  cars.reserve(args.count);
  std::vector<std::shared_ptr<view::WireWatch>> watches;
  std::vector<std::string> listing;  // "<name> <address>" per car
  // Serial cars are at most kMaxSerialCars, and their paths are what a
  // user opens, so each is listed.
  const bool list_each = args.verbose || args.count <= kCarsListed || serial;
  for (std::size_t i = 0; i < args.count; ++i) {
    mocks::CarOptions options = base;
    options.name = "car" + std::to_string(i);
    options.seed = mocks::car_seed(seed, i);
    // Switched on one after another across a STAT period: a fleet's
    // telemetry and control ticks spread out instead of all cars waking in
    // the same instant, which would hold up every answer behind a burst of
    // N cars' work (docs/performance.md, the fleet).
    const auto& logi_config = options.configs.logi;
    options.configs.logi.boot_offset = logi_config.stat_period * static_cast<std::int64_t>(i) /
                                       static_cast<std::int64_t>(args.count);
    if (!args.quiet) {
      options.configs.wr8.log = [log, name = options.name](const std::string& l) {
        log(name + ": " + l);
      };
      options.configs.svgui.log = options.configs.wr8.log;
    }
    RunningCar running;
    try {
      running.car = std::make_unique<mocks::MockCar>(std::move(options));
    } catch (const std::exception& e) {
      std::cerr << "hil mock: cannot build the car: " << e.what() << '\n';
      return 1;
    }
    for (const auto& b : behaviours)
      running.car->firmware().arm(b);
    mocks::ServerOptions server;
    server.listen = endpoint_for(args, *kind, i);
    server.faults = faults;
    server.seed = mocks::car_seed(seed, i);
    server.wire_log_path = args.wire_log;
    server.name = running.car->name();
    if (!args.quiet) server.log = log;
    if (args.view) {
      watches.push_back(std::make_shared<view::WireWatch>(running.car->firmware().adapter()));
      server.observers.push_back(watches.back());
    }
    running.server =
        std::make_unique<mocks::MockServer>(context, running.car->firmware(), std::move(server));
    const auto listening = endpoint_for(args, *kind, i);
    try {
      running.server->start();
    } catch (const std::exception& e) {
      std::cerr << "hil mock: cannot listen on " << link::to_uri(listening) << ": " << e.what();
      if (std::holds_alternative<link::TcpEndpoint>(listening))
        std::cerr << " (is another hil mock running? choose another --port)";
      std::cerr << '\n';
      return 1;
    }
    listing.push_back(running.car->name() + " " + running.server->address());
    if (list_each || i == 0 || i + 1 == args.count) {
      if (!list_each && i + 1 == args.count) {
        const unsigned second = port_of(cars.at(1).server->address());
        const unsigned last_but_one = port_of(cars.back().server->address());
        std::cout << "hil mock " << args.car << ": ... " << args.count - 2 << " more cars";
        if (args.port && *args.port != 0)
          std::cout << " on ports " << second << ".." << last_but_one << " (car N on " << *args.port
                    << "+N)";
        else
          std::cout << " on free ports";
        std::cout << "; -v lists each, --ports-file writes them to a file\n";
      }
      std::cout << "hil mock " << args.car << ": " << running.car->name() << " "
                << how_to_connect(listening, running.server->address()) << '\n';
    }
    cars.push_back(std::move(running));
  }
  if (!args.ports_file.empty() && !write_ports_file(args.ports_file, listing)) {
    std::cerr << "hil mock: cannot write --ports-file " << args.ports_file << '\n';
    return 1;
  }
  if (args.bind != "127.0.0.1" && args.bind != "localhost" && args.bind != "::1" &&
      !std::holds_alternative<link::PtyEndpoint>(mocks::default_endpoint(*kind, 0))) {
    std::cerr << "warning: listening on " << args.bind << ", reachable from other machines\n";
  }
  std::cout << "world " << (args.world.empty() ? "built-in warehouse" : args.world) << ", "
            << faults.rules.size() << " fault rule(s), " << behaviours.size()
            << " behaviour(s), seed " << seed << " (replay with --seed " << seed
            << "); Ctrl-C stops" << std::endl;

  // Declared after the cars: destroyed first, so the page never outlives them.
  std::unique_ptr<view::LiveModel> view_model;
  std::unique_ptr<view::LiveViewServer> view_server;
  if (args.view) {
    std::vector<view::ViewedCar> viewed;
    const std::string faults_text = args.faults.empty() ? std::string() : read_text(args.faults);
    for (std::size_t i = 0; i < cars.size(); ++i)
      viewed.push_back(view::ViewedCar{cars[i].car.get(), cars[i].server.get(), watches[i], faults,
                                       faults_text});
    view_model = std::make_unique<view::LiveModel>(std::move(viewed));
    view::ViewOptions options;
    options.port = *view_port;
    view_server = std::make_unique<view::LiveViewServer>(io, executor, *view_model, options);
    try {
      view_server->start();
    } catch (const std::exception& e) {
      std::cerr << "hil mock: --view: " << e.what() << " (choose another port: --view PORT)\n";
      return 1;
    }
    std::cout << "view: " << view_server->url() << std::endl;
  }

  std::unique_ptr<DeskConsole> console;
  if (DeskConsole::available(args.commands)) {
    try {
      console = std::make_unique<DeskConsole>(io, cars, log);
    } catch (const std::system_error& e) {
      std::cerr << "hil mock: --commands needs stdin to be a terminal or a pipe: " << e.what()
                << '\n';
      return 2;
    }
    std::cout << "type 'help' for desk commands (a parcel in front of the car, fault, hangup, ...)"
              << std::endl;
    console->start();
  }

  // The status line is redrawn five times a second while it is on.
  std::function<void()> redraw;
  redraw = [&] {
    if (!status.enabled()) return;
    status.show(status_text(cars));
    executor.call_after(link::milliseconds(200), redraw);
  };
  if (status.enabled()) redraw();

  signals.async_wait([&](const std::error_code& ec, int) {
    if (ec) return;
    status.end();
    std::uint64_t served = 0;
    for (auto& c : cars) {
      served += c.server->clients_served();
      c.server->close();
    }
    if (console) console->stop();
    if (view_server) view_server->stop();
    std::cout << "hil mock: stopping (" << served << " client(s) served)" << std::endl;
    executor.call_after(link::milliseconds(100), [&io] { io.stop(); });
  });
  io.run();
  return 0;
}

}  // namespace

void register_mock(CLI::App& app, std::function<int()>& run) {
  auto args = std::make_shared<MockArgs>();
  auto* cmd = app.add_subcommand(
      "mock", "Run mock cars on this machine for a client or UI to talk to (real time)");
  cmd->add_option("car", args->car, "Which car: logi, wr8 (TCP), arduino, leka (pty)")
      ->required()
      ->check(CLI::IsMember({"logi", "wr8", "arduino", "leka"}));
  cmd->add_option("--profile", args->profile,
                  "The car's profile, its dialect (hil profiles CAR lists them; default: the "
                  "car's default profile), e.g. arduino --profile readme plays the README's board");
  cmd->add_option(
      "--bind", args->bind,
      "Address TCP cars listen on (default 127.0.0.1; 0.0.0.0 opens it to the network)");
  cmd->add_option("--port", args->port,
                  "First TCP port (default 9000 for logi, 9100 for wr8; car N uses PORT+N; 0 picks "
                  "free ports)");
  cmd->add_option(
      "--pty", args->pty,
      "Serial cars: symlink to the first pty (default /tmp/hil-<car>0; car N counts up)");
  cmd->add_option("--baud", args->baud,
                  "Serial cars: line rate (default 9600 for arduino, 115200 for leka; 0 unpaced)");
  cmd->add_option("--reply-latency", args->reply_latency,
                  "The firmware's processing time before each answer, e.g. 20ms; 0 answers in "
                  "the same instant (default: the profile's, `hil profiles`; a serial car's bytes "
                  "also take their time on the line at --baud)");
  cmd->add_option("--reset-ms", args->reset_ms,
                  "Serial cars: bytes sent this long after opening the port are lost, as when an "
                  "Arduino resets (default 0)");
  cmd->add_option("--world", args->world, "World file (default: the built-in warehouse)");
  cmd->add_option("--faults", args->faults, "Fault profile (YAML, docs/faults.md)");
  cmd->add_option("--behaviours", args->behaviours,
                  "Scripted behaviours to arm at start (YAML, docs/mocks.md)");
  cmd->add_option("--seed", args->seed,
                  "Seed for sensor noise and faults (printed when chosen at random)");
  cmd->add_option("--log", args->wire_log,
                  "Write every byte of every connection to an NDJSON wire log");
  cmd->add_option("--count", args->count,
                  "Run N independent cars on consecutive ports or ptys (TCP cars up to " +
                      std::to_string(kMaxTcpCars) + ", serial cars up to " +
                      std::to_string(kMaxSerialCars) + ")")
      ->check(CLI::Range(std::size_t{1}, kMaxTcpCars));
  cmd->add_option("--ports-file", args->ports_file,
                  "Write one line per car, its name and where it listens, once every car "
                  "listens (for scripts; with --port 0 the ports are not consecutive)");
  cmd->add_option("--auth", args->auth,
                  "WR8: the 10-character authentication string (a wrong one is refused "
                  "after 1 s, doubling per failure in a row up to 30 s; failures are logged "
                  "without the string); svgui profiles: the text an AUTH must end with "
                  "(default konnichiwa; a wrong one is left unanswered, the connection open)");
  cmd->add_option("--data-hz", args->data_hz,
                  "WR8: DATA packets per second (default 10; svgui-head: fixed, HIGH-FREQ "
                  "20 and LOW-FREQ 1 per second)")
      ->check(CLI::Range(0.1, 1000.0));
  cmd->add_flag("-q,--quiet", args->quiet, "No line per connection, fault and WR8 login failure");
  cmd->add_flag("-v,--verbose", args->verbose,
                "One line per car even with more than " + std::to_string(kCarsListed) +
                    " cars (else the first, the last and a summary)");
  cmd->add_flag("--commands", args->commands,
                "Read desk commands from stdin even when it is not a terminal (they are read "
                "from a terminal anyway; type 'help')");
  auto* view_option =
      cmd->add_option("--view", args->view_port,
                      "Serve a live view of the cars on http://127.0.0.1:PORT/ (default " +
                          std::to_string(kDefaultViewPort) +
                          "; 0 picks a free port): the arena, the car, its sensors, the wire, and "
                          "a panel for faults and behaviours (docs/live-view.md)")
          ->expected(0, 1);
  cmd->add_flag("--no-status", args->no_status,
                "No status line (it is off anyway when not a terminal)");
  cmd->footer(
      "Examples:\n"
      "  hil mock logi                                 # LOGI car on tcp://127.0.0.1:9000\n"
      "  hil mock wr8 --count 3 --port 9100            # three WR8 vehicles on 9100..9102\n"
      "  hil mock logi --count 1000 -q                 # a fleet of LOGI cars on 9000..9999\n"
      "  hil mock arduino --pty /tmp/robot0            # open /tmp/robot0 at 9600 baud\n"
      "  hil mock logi --faults scenarios/faults/sticky-packets.yaml --log wire.ndjson\n"
      "  hil mock logi --view                          # and watch it on http://127.0.0.1:8080/\n"
      "Stops cleanly on Ctrl-C (SIGINT) or SIGTERM.");
  cmd->callback([&run, args, view_option] {
    args->view = view_option->count() > 0;
    run = [args] { return run_mock(*args); };
  });
}

}  // namespace hil::apps
