// hil conform: run a car's conformance probe against a car and record it
// (`probe`), and compare hil's mock with a recorded probe (`check`).
#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <memory>

#include "apps/hil/cli_common.hpp"
#include "conform/check.hpp"
#include "conform/probe_runner.hpp"
#include "conform/report.hpp"
#include "harness/atomic_file.hpp"
#include "link/endpoint.hpp"
#include "mocks/avr/firmware_source.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::apps {

namespace {

std::atomic<bool> g_interrupted{false};

extern "C" void on_interrupt(int) {
  g_interrupted = true;
}

// A target the probe may move without --yes: a TCP address on this
// machine, or a pseudo-terminal (hil mock's serial cars are ptys; a real
// board is a /dev/ttyUSB* or /dev/ttyACM* device).
std::optional<std::string> why_not_safe(const link::Endpoint& target) {
  if (const auto* tcp = std::get_if<link::TcpEndpoint>(&target)) {
    const auto& h = tcp->host;
    if (h == "localhost" || h == "::1" || h.starts_with("127.")) return std::nullopt;
    return "tcp host " + h + " is not this machine";
  }
  if (const auto* pty = std::get_if<link::PtyEndpoint>(&target)) {
    std::error_code ec;
    const auto real = std::filesystem::canonical(pty->path, ec);
    if (!ec && real.string().starts_with("/dev/pts/")) return std::nullopt;
    return pty->path + " is not a pseudo-terminal";
  }
  return std::nullopt;  // mem:// lives in this process
}

int run_probe_command(const std::string& car_name, const std::string& target_uri,
                      const std::string& profile, const std::string& output, bool yes, bool quiet) {
  const auto car = mocks::parse_car_kind(car_name);
  if (!car) {
    std::cerr << "hil conform probe: unknown car '" << car_name << "' (expected "
              << mocks::kCarKindNames.list(" or ") << ")\n";
    return 2;
  }
  conform::Probe probe;
  link::Endpoint target;
  try {
    probe = conform::make_probe(*car, profile);
    target = link::parse_endpoint(target_uri);
  } catch (const std::exception& e) {
    std::cerr << "hil conform probe: " << e.what() << "\n";
    return 2;
  }
  if (auto why = why_not_safe(target); why && !yes) {
    std::cerr << "hil conform probe: the probe moves the car (slowly, for short moves, and stops "
                 "it at the end), and "
              << *why << ": check the car has room to move, then add --yes\n";
    return 2;
  }
  std::shared_ptr<link::WireLog> log;
  try {
    log = link::open_capture_log(output, link::protocol_adapter(car_name, probe.profile));
  } catch (const std::exception& e) {
    std::cerr << "hil conform probe: " << e.what() << "\n";
    return 2;
  }
  std::cerr << "hil conform probe: " << probe.version << ", " << probe.exchanges.size()
            << " exchanges (about "
            << std::chrono::duration_cast<std::chrono::seconds>(probe.duration()).count()
            << " s) against " << link::to_uri(target) << ", profile " << probe.profile << "\n";
  auto driver = harness::make_run_driver(true);
  link::CaptureRecorder recorder(
      conform::capture_header(probe, link::to_uri(target), link::wall_time_us()), log);
  conform::ProbeHooks hooks;
  if (!quiet) hooks.progress = [](const std::string& line) { std::cerr << "  " << line << "\n"; };
  hooks.interrupted = [] { return g_interrupted.load(); };
  g_interrupted = false;
  auto previous_int = std::signal(SIGINT, on_interrupt);
  auto previous_term = std::signal(SIGTERM, on_interrupt);
  const auto run = conform::run_probe(*driver, target, probe, recorder, hooks);
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  if (log->error()) {
    std::cerr << "hil conform probe: writing " << output << " failed: " << log->error().message()
              << "\n";
    return 1;
  }
  if (run.error) {
    std::cerr << "hil conform probe: " << *run.error << " (after " << run.capture.exchanges.size()
              << " of " << probe.exchanges.size() << " exchanges; " << output
              << " keeps what was recorded)\n";
    return 1;
  }
  std::cout << "probe: " << run.capture.exchanges.size() << " exchanges recorded in " << output
            << "\nnext: hil conform check " << output << " --all-profiles\n";
  return 0;
}

// --sketch or --elf: the probe against a real firmware on the emulated
// board, in virtual time (seconds, not the probe's minutes).
int run_sketch_probe(const mocks::avr::FirmwareSource& source, const std::string& output,
                     bool quiet) {
  mocks::CarOptions options;
  options.kind = mocks::CarKind::arduino;
  try {
    options.configs.avr = mocks::avr::resolve_firmware(source);
  } catch (const mocks::avr::SketchBuildError& e) {
    std::cerr << "hil conform probe: " << e.what() << "\n" << e.diagnostics();
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "hil conform probe: " << e.what() << "\n";
    return 2;
  }
  const conform::Probe probe = conform::make_probe(mocks::CarKind::arduino, "");
  std::shared_ptr<link::WireLog> log;
  try {
    log = link::open_capture_log(output, link::protocol_adapter("arduino", probe.profile));
  } catch (const std::exception& e) {
    std::cerr << "hil conform probe: " << e.what() << "\n";
    return 2;
  }
  const std::string target = "avr:" + (source.sketch.empty() ? source.elf : source.sketch).string();
  if (!quiet)
    std::cerr << "hil conform probe: " << probe.version << ", " << probe.exchanges.size()
              << " exchanges against " << target << " on the emulated ATmega328P (virtual time)\n";
  const auto capture = conform::probe_in_virtual_time(probe, std::move(options), target, log);
  if (log->error()) {
    std::cerr << "hil conform probe: writing " << output << " failed: " << log->error().message()
              << "\n";
    return 1;
  }
  std::cout << "probe: " << capture.exchanges.size() << " exchanges recorded in " << output
            << "\nnext: hil conform check " << output << " --all-profiles\n";
  return 0;
}

struct CheckArgs {
  std::string capture;
  std::string profile;
  bool all_profiles = false;
  std::string junit;
  std::string html;
  std::uint64_t seed = 1;
};

int run_check_command(const CheckArgs& args) {
  link::Capture capture;
  conform::CheckResult result;
  try {
    capture = link::read_capture(args.capture);
    result = conform::check(capture, {}, args.seed);
  } catch (const std::exception& e) {
    std::cerr << "hil conform check: " << e.what() << "\n";
    return 2;
  }
  conform::ReportOptions options;
  options.capture_path = args.capture;
  options.all_profiles = args.all_profiles;
  if (args.all_profiles) {
    options.profile = result.ranking().front();
  } else if (!args.profile.empty()) {
    const auto problem = protocol::car_profile_problem(capture.header.car, args.profile);
    if (!problem.empty()) {
      std::cerr << "hil conform check: --profile: " << problem << "\n";
      return 2;
    }
    options.profile = protocol::find_car_profile(capture.header.car, args.profile).name;
  } else {
    options.profile = capture.header.profile;
  }
  conform::write_console(std::cout, capture, result, options);
  try {
    if (!args.junit.empty())
      harness::write_file_atomically(args.junit, conform::junit_xml(capture, result, options));
    if (!args.html.empty())
      harness::write_file_atomically(args.html, conform::html_page(capture, result, options));
  } catch (const std::exception& e) {
    std::cerr << "hil conform check: " << e.what() << "\n";
    return 2;
  }
  return result.of(options.profile).all_match() ? 0 : 1;
}

}  // namespace

void register_conform(CLI::App& app, std::function<int()>& run) {
  auto* conform = app.add_subcommand(
      "conform", "Probe a car, and measure how far hil's mock is from it (docs/conformance.md)");
  conform->require_subcommand(1);

  struct ProbeArgs {
    std::string car;
    std::string target;
    std::string profile;
    std::string output;
    bool yes = false;
    bool quiet = false;
    mocks::avr::FirmwareSource firmware;
  };
  auto probe_args = std::make_shared<ProbeArgs>();
  auto* probe = conform->add_subcommand(
      "probe", "Run the car's probe against a car (real time) and record it as a capture");
  probe->add_option("car", probe_args->car, "logi, wr8, arduino or leka")->required();
  auto* target = probe->add_option(
      "--target", probe_args->target,
      "The car: tcp://HOST:PORT, or pty:///dev/ttyUSB0?baud=9600 for a serial car");
  auto* sketch = probe->add_option(
      "--sketch", probe_args->firmware.sketch,
      "Arduino: instead of a car, this sketch built and run on the emulated ATmega328P, probed "
      "in virtual time (docs/firmware.md)");
  auto* elf = probe->add_option("--elf", probe_args->firmware.elf,
                                "Arduino: as --sketch, for a firmware image built already");
  probe->add_option("--pins", probe_args->firmware.pins,
                    "With --sketch or --elf: the pin map (YAML)");
  sketch->excludes(elf);
  target->excludes(sketch)->excludes(elf);
  probe->add_option("--profile", probe_args->profile,
                    "The profile the probe's frames are written in (hil profiles CAR; default: "
                    "the car's default)");
  probe->add_option("-o,--output", probe_args->output, "The capture to write (NDJSON)")->required();
  probe->add_flag("--yes", probe_args->yes,
                  "Allow moving a car that is not on this machine or not on a pseudo-terminal");
  probe->add_flag("-q,--quiet", probe_args->quiet, "Do not print each exchange as it starts");
  probe->footer(
      "The probe moves the car slowly for short moves and stops it at the end; Ctrl-C sends the "
      "stop at once.\nExamples:\n"
      "  hil conform probe logi --target tcp://192.168.4.1:8080 --yes -o logi-car.ndjson\n"
      "  hil conform probe arduino --target 'pty:///dev/ttyUSB0?baud=9600' --yes -o robot.ndjson\n"
      "  hil conform probe wr8 --profile svgui-head --target tcp://127.0.0.1:5556 -o wr8.ndjson\n"
      "  hil conform probe arduino --sketch robot/robot.ino -o sketch.ndjson");
  probe->callback([&run, probe_args] {
    run = [probe_args] {
      const auto& firmware = probe_args->firmware;
      if (!firmware.sketch.empty() || !firmware.elf.empty()) {
        if (probe_args->car != "arduino") {
          std::cerr << "hil conform probe: --sketch and --elf run Arduino firmware; a "
                    << probe_args->car << " car has no such board\n";
          return 2;
        }
        return run_sketch_probe(firmware, probe_args->output, probe_args->quiet);
      }
      if (probe_args->target.empty()) {
        std::cerr << "hil conform probe: --target is required (or --sketch/--elf for an Arduino "
                     "sketch on the emulated board)\n";
        return 2;
      }
      return run_probe_command(probe_args->car, probe_args->target, probe_args->profile,
                               probe_args->output, probe_args->yes, probe_args->quiet);
    };
  });

  auto check_args = std::make_shared<CheckArgs>();
  auto* check = conform->add_subcommand(
      "check", "Replay a capture's probe against hil's mock (virtual time) and compare");
  check->add_option("capture", check_args->capture, "A capture written by hil conform probe")
      ->required();
  auto* profile = check->add_option(
      "--profile", check_args->profile,
      "The mock's profile to compare with (default: the profile the capture was probed in)");
  check
      ->add_flag("--all-profiles", check_args->all_profiles,
                 "Rank every profile of the car by matches and show the best")
      ->excludes(profile);
  check->add_option("--junit", check_args->junit, "Write JUnit XML (one test case per exchange)");
  check->add_option("--html", check_args->html, "Write the report as one HTML page");
  check->add_option("--seed", check_args->seed, "The mock's seed (sensor noise)");
  check->footer(
      "Exit status: 0 when every exchange matches, 1 when one differs, 2 for a capture or an "
      "option that cannot be used.\nExamples:\n"
      "  hil conform check robot.ndjson --all-profiles\n"
      "  hil conform check robot.ndjson --profile firmware --junit conform.xml --html "
      "conform.html");
  check->callback(
      [&run, check_args] { run = [check_args] { return run_check_command(*check_args); }; });
}

}  // namespace hil::apps
