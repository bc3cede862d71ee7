#include "apps/hil/mock_options.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <random>

#include "base/duration.hpp"
#include "link/capture/probe_capture.hpp"
#include "link/faults/profile_yaml.hpp"
#include "mocks/avr/firmware_source.hpp"
#include "mocks/behaviour_yaml.hpp"
#include "protocol/common/car_profile.hpp"
#include "sim/arena_yaml.hpp"

namespace hil::apps {
namespace {

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

// --world, --faults and --behaviours.
void load_files(const MockCarArgs& args, MockPlan& plan) {
  try {
    if (!args.world.empty()) plan.base.arena = sim::load_arena(args.world);
    if (!args.faults.empty()) plan.faults = link::load_fault_profile(args.faults);
    if (!args.behaviours.empty()) plan.behaviours = mocks::load_behaviours(args.behaviours);
  } catch (const std::exception& e) {
    throw MockStartError{e.what(), 1};
  }
}

// --profile, --auth, --reply-latency and --data-hz on the car's configs.
void configure_car(const MockCarArgs& args, const std::string& profile,
                   mocks::FirmwareConfigs& configs, mocks::CarKind kind) {
  try {
    mocks::apply_profile(configs, kind, profile);
  } catch (const protocol::ProfileError& e) {
    throw MockStartError{std::string("--profile: ") + e.what(), 2};
  }
  if (!args.auth.empty()) {
    if (args.auth.size() != protocol::wr8::kAuthTextBytes) {
      throw MockStartError{"--auth must be exactly " +
                               std::to_string(protocol::wr8::kAuthTextBytes) + " characters, got " +
                               std::to_string(args.auth.size()) + " (\"" + args.auth + "\")",
                           2};
    }
    std::copy(args.auth.begin(), args.auth.end(), configs.wr8.profile.auth_text.begin());
    configs.svgui.auth_suffix = args.auth;
  }
  if (!args.reply_latency.empty()) {
    const auto latency = parse_duration(args.reply_latency);
    if (!latency) {
      throw MockStartError{"--reply-latency must be a duration with a unit (20ms, 1.5s), got '" +
                               args.reply_latency + "'",
                           2};
    }
    configs.reply_latency = *latency;
  }
  if (args.data_hz) {
    if (configs.svgui.version == protocol::wr8::svgui::Version::head) {
      throw MockStartError{
          "--data-hz: the svgui-head vehicle sends HIGH-FREQ DATA every 50 ms "
          "and LOW-FREQ every 1000 ms, as the real program does",
          2};
    }
    const auto period = std::chrono::duration_cast<link::Duration>(
        std::chrono::duration<double>(1.0 / *args.data_hz));
    configs.wr8.data_period = period;
    configs.svgui.v2019_data_period = period;
  }
}

// --replay and --unmatched: the capture read and checked against the car
// and --profile; the car then plays the capture's profile.
void load_replay(const MockCarArgs& args, MockPlan& plan) {
  plan.profile = args.profile;
  if (args.replay.empty()) return;
  std::shared_ptr<const link::Capture> capture;
  try {
    capture = std::make_shared<const link::Capture>(link::read_capture(args.replay));
  } catch (const link::CaptureError& e) {
    throw MockStartError{std::string("--replay: ") + e.what(), 2};
  }
  const auto& header = capture->header;
  if (header.car != args.kind) {
    throw MockStartError{"--replay: " + args.replay + " is a capture of a " + header.car +
                             " car, not of a " + args.kind + " car (hil mock " + header.car +
                             " --replay " + args.replay + " plays it)",
                         2};
  }
  std::string profile;
  try {
    profile = std::string(protocol::find_car_profile(header.car, header.profile).name);
  } catch (const protocol::ProfileError& e) {
    throw MockStartError{"--replay: " + args.replay + ": " + e.what(), 2};
  }
  if (!args.profile.empty()) {
    if (const auto problem = protocol::car_profile_problem(args.kind, args.profile);
        !problem.empty()) {
      throw MockStartError{"--profile: " + problem, 2};
    }
    if (protocol::find_car_profile(args.kind, args.profile).name != profile) {
      throw MockStartError{"--profile " + args.profile + ": " + args.replay +
                               " was recorded in profile " + profile +
                               " (leave --profile out with --replay)",
                           2};
    }
  }
  plan.profile = profile;
  mocks::ReplaySpec spec;
  spec.path = args.replay;
  spec.capture = std::move(capture);
  spec.unmatched = mocks::parse_unmatched(args.unmatched).value_or(mocks::Unmatched::mock);
  plan.base.replay = std::move(spec);
}

// --sketch, --elf and --pins: the firmware built (or found in the cache)
// and checked, the pin map read, before any car starts.
void load_firmware(const MockCarArgs& args, MockPlan& plan) {
  if (args.sketch.empty() && args.elf.empty()) {
    if (!args.pins.empty()) throw MockStartError{"--pins needs --sketch or --elf", 2};
    if (!args.board_startup.empty())
      throw MockStartError{"--board-startup needs --sketch or --elf", 2};
    return;
  }
  if (args.kind != "arduino") {
    throw MockStartError{"--sketch and --elf run Arduino firmware on an emulated ATmega328P; a " +
                             args.kind + " car has no such board",
                         2};
  }
  if (!args.replay.empty())
    throw MockStartError{"--replay plays a capture; leave out --sketch and --elf", 2};
  mocks::avr::FirmwareSource source;
  source.sketch = args.sketch;
  source.elf = args.elf;
  source.pins = args.pins;
  if (!args.board_startup.empty()) {
    const auto startup = parse_duration(args.board_startup);
    if (!startup || *startup > std::chrono::seconds(10)) {
      throw MockStartError{
          "--board-startup takes a duration of at most 10s (e.g. 0ms, 66ms), got \"" +
              args.board_startup + "\"",
          2};
    }
    source.startup_delay = *startup;
  }
  try {
    plan.base.configs.avr = mocks::avr::resolve_firmware(source);
  } catch (const mocks::avr::SketchBuildError& e) {
    std::string message = std::string("--sketch: ") + e.what();
    if (!e.diagnostics().empty()) message += "\n" + e.diagnostics();
    throw MockStartError{message, 1};
  } catch (const std::exception& e) {
    throw MockStartError{std::string(args.sketch.empty() ? "--elf: " : "--sketch: ") + e.what(), 2};
  }
}

// --rfc2217 for this kind of car, with --pty and --count.
void plan_rfc2217(const MockArgs& args, MockPlan& plan) {
  if (args.listen.rfc2217.empty()) return;
  if (!plan.serial) {
    throw MockStartError{"--rfc2217 serves a serial car (arduino, leka); a " + args.car.kind +
                             " car listens on TCP (--bind, --port)",
                         2};
  }
  if (!args.listen.pty.empty())
    throw MockStartError{"--rfc2217 and --pty each give the car's serial port; choose one", 2};
  const auto e = parse_rfc2217_option(args.listen.rfc2217);
  if (e.port != 0 && e.port + args.count - 1 > 65535) {
    throw MockStartError{"--rfc2217 port " + std::to_string(e.port) + " with --count " +
                             std::to_string(args.count) +
                             " runs past port 65535 (car N listens on PORT+N); choose a lower "
                             "port or port 0",
                         2};
  }
  plan.rfc2217 = e;
}

// --count and --port for this kind of car, and the open files they need.
void check_fleet(const MockArgs& args, bool serial) {
  if (serial && args.count > kMaxSerialCars) {
    throw MockStartError{"--count for serial cars is at most " + std::to_string(kMaxSerialCars) +
                             " (each holds a pty from the pool every terminal shares), got " +
                             std::to_string(args.count),
                         2};
  }
  const auto& port = args.listen.port;
  if (!serial && port && *port != 0 && *port + args.count - 1 > 65535) {
    throw MockStartError{"--port " + std::to_string(*port) + " with --count " +
                             std::to_string(args.count) +
                             " runs past port 65535 (car N listens on PORT+N); choose a lower "
                             "--port or --port 0",
                         2};
  }
  if (const auto problem = make_room_for_descriptors(args.count, serial))
    throw MockStartError{*problem, 1};
}

}  // namespace

link::Rfc2217Endpoint parse_rfc2217_option(const std::string& text) {
  const auto bad = [&text]() {
    return MockStartError{
        "--rfc2217 takes [ADDR:]PORT, e.g. 4000, 127.0.0.1:4000 or "
        "0.0.0.0:4000 (PORT 0..65535, 0 picks a free one), got \"" +
            text + "\"",
        2};
  };
  const std::size_t colon = text.rfind(':');
  const bool bracketed = !text.empty() && text.front() == '[';
  if (colon == std::string::npos && bracketed) throw bad();
  std::string host = colon == std::string::npos ? "" : text.substr(0, colon);
  const std::string port = colon == std::string::npos ? text : text.substr(colon + 1);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  if (colon != std::string::npos && host.empty()) throw bad();
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos)
    throw bad();
  const unsigned long number = std::stoul(port);
  if (number > 65535) throw bad();
  link::Rfc2217Endpoint e;
  if (!host.empty()) e.host = host;
  e.port = static_cast<std::uint16_t>(number);
  return e;
}

bool is_loopback(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "::1";
}

MockPlan plan_mock(const MockArgs& args) {
  MockPlan plan;
  plan.kind = *mocks::parse_car_kind(args.car.kind);
  plan.base.kind = plan.kind;
  // A mock on a shared machine is a target for guessing the login: each
  // failure in a row doubles the refusal delay up to 30 s. Scenarios keep
  // the library's constant 1 s, which their timings rely on.
  plan.base.configs.wr8.wrong_auth_max_delay = link::seconds(30);
  load_files(args.car, plan);
  load_replay(args.car, plan);
  load_firmware(args.car, plan);
  configure_car(args.car, plan.profile, plan.base.configs, plan.kind);
  plan.serial = std::holds_alternative<link::PtyEndpoint>(
      mocks::default_endpoint(plan.kind, 0, plan.profile));
  plan_rfc2217(args, plan);
  check_fleet(args, plan.serial);
  plan.seed = args.car.seed ? *args.car.seed : std::random_device{}();
  const auto view_port = parse_view_port(args.desk.view_port);
  if (args.desk.view && !view_port) {
    throw MockStartError{"--view takes a port number 0..65535 (0: any free port), got \"" +
                             args.desk.view_port + "\"",
                         2};
  }
  plan.view_port = view_port.value_or(kDefaultViewPort);
  return plan;
}

}  // namespace hil::apps
