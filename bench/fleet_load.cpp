// A fleet in real time: `hil mock logi --count N` against N load clients,
// each holding a LOGI session (a command at a steady rate, every STAT and
// every FB read), measured side by side with a plain echo round trip on the
// same loopback in the same run. Prints a Markdown table.
//
// The mock runs as its own process (as users run it), so its CPU time and
// resident memory come from /proc (bench/fleet_mock.*). Memory per car is
// the mock's VmRSS minus that of a one-car mock started in the same run,
// over N - 1. The clients are in bench/fleet_clients.*.
//
// Usage: fleet_load [--count N] [--seconds S] [--rate CMDS_PER_S] [--parked] [--hil PATH]
//                   [--sweep [N,N,...]] [--markdown FILE]
//                   [--max-ratio K --floor-ms F]   (a check: exit 1 on a regression)

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench/fleet_clients.hpp"
#include "bench/fleet_mock.hpp"

namespace hil::bench::fleet {
namespace {

// The fleet targets for N = 1,000 on 2 cores (docs/performance.md).
constexpr double kTargetJitterP99Ms = 10;
constexpr double kTargetFeedbackP99Ms = 5;
constexpr double kTargetKibPerCar = 1024;
// One io_context thread serves every car: near a whole core it is saturated.
constexpr double kCpuSaturatedCores = 0.9;

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::ceil(p / 100 * static_cast<double>(v.size()))) - 1;
  return v[std::min(i, v.size() - 1)];
}

// ------------------------------------------------------------------ one run

struct Options {
  std::size_t count = 1000;
  double seconds = 30;
  double rate_hz = 1;
  bool parked = false;
  std::string hil = HIL_BINARY;
  std::vector<std::size_t> sweep;
  std::string markdown;
  std::optional<double> max_ratio;
  double floor_ms = 0;
};

struct Result {
  std::size_t count = 0;
  double seconds = 0;
  std::string failure;  // the mock did not start or the clients could not connect
  Measurements m;
  double stat_expected = 0;
  double cpu_cores = 0;        // mock CPU over the window, in cores
  double waited_fraction = 0;  // of the window, the mock runnable but not running
  double rss_kib = 0;
  double baseline_rss_kib = 0;
  std::size_t fds = 0;
  double driver_cpu_cores = 0;
  std::string load_before;
  std::string load_after;

  double jitter_p50() const { return percentile(m.stat_jitter_ms, 50); }
  double jitter_p99() const { return percentile(m.stat_jitter_ms, 99); }
  double jitter_max() const {
    return m.stat_jitter_ms.empty()
               ? 0
               : *std::max_element(m.stat_jitter_ms.begin(), m.stat_jitter_ms.end());
  }
  double fb_p50() const { return percentile(m.feedback_ms, 50); }
  double fb_p99() const { return percentile(m.feedback_ms, 99); }
  double echo_p50() const { return percentile(m.echo_ms, 50); }
  double echo_p99() const { return percentile(m.echo_ms, 99); }
  double kib_per_car() const {
    return count > 1 ? (rss_kib - baseline_rss_kib) / static_cast<double>(count - 1) : 0;
  }
  double stat_lost_fraction() const {
    return stat_expected > 0 ? std::max(0.0, 1 - static_cast<double>(m.stats) / stat_expected) : 0;
  }

  // What misses its target, in the order a user notices it; empty: none.
  std::vector<std::string> broken() const {
    std::vector<std::string> b;
    if (!failure.empty()) return {failure};
    if (cpu_cores >= kCpuSaturatedCores) b.push_back("CPU (the mock's thread is saturated)");
    if (jitter_p99() >= kTargetJitterP99Ms) b.push_back("STAT jitter");
    if (stat_lost_fraction() > 0.01) b.push_back("STATs missing");
    if (fb_p99() >= kTargetFeedbackP99Ms) b.push_back("feedback latency");
    if (m.feedback_missing > m.commands / 100) b.push_back("feedback missing");
    if (kib_per_car() >= kTargetKibPerCar) b.push_back("memory per car");
    if (m.disconnects > 0) b.push_back("connections dropped");
    return b;
  }
};

Result run_fleet(const Options& o, std::size_t count) {
  Result r;
  r.count = count;
  r.seconds = o.seconds;
  r.load_before = loadavg();
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("hil-fleet-" + std::to_string(::getpid())))
          .string();
  std::filesystem::create_directories(dir);

  // The empty baseline: a one-car mock, idle, in the same run.
  {
    MockProcess one(o.hil, 1, dir);
    if (one.wait_for_ports(std::chrono::seconds(30)).empty()) {
      r.failure = "the one-car mock did not start: " + one.output();
      return r;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    r.baseline_rss_kib = sample(one.pid()).rss_kib;
  }

  if (fd_limit() < count + 64) {
    r.failure = "fds (this driver may open " + std::to_string(fd_limit()) + " files, needs " +
                std::to_string(count + 64) + ")";
    return r;
  }
  MockProcess mock(o.hil, count, dir);
  const auto ports = mock.wait_for_ports(std::chrono::seconds(60 + count / 20));
  if (ports.size() != count) {
    std::string out = mock.output();
    while (!out.empty() && out.back() == '\n')
      out.pop_back();
    r.failure = "the mock did not start (" + out + ")";
    return r;
  }

  EchoServer echo;
  asio::io_context io;
  Measurements& m = r.m;
  Window window;
  const auto connect_at = Clock::now();
  // Connections, then 2 s for every car's first STAT and the mode change,
  // then the measured window.
  window.start =
      connect_at + std::chrono::seconds(2) + std::chrono::milliseconds(static_cast<long>(count));
  window.end = window.start + std::chrono::milliseconds(static_cast<long>(o.seconds * 1000));
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / o.rate_hz));
  std::vector<std::shared_ptr<CarClient>> clients;
  for (std::size_t i = 0; i < count; ++i) {
    auto c = std::make_shared<CarClient>(io, m, window, o.parked);
    // Spread evenly: car i's commands come at i/N of the period.
    const auto phase = period * static_cast<long>(i) / static_cast<long>(count);
    c->start(ports[i], window.start - period + phase, period);
    clients.push_back(c);
  }
  auto echo_client = std::make_shared<EchoClient>(io, m, window);
  echo_client->start(echo.port());

  ProcSample before;
  double driver_before = 0;
  asio::steady_timer at_start(io);
  at_start.expires_at(window.start);
  at_start.async_wait([&](std::error_code) {
    before = sample(mock.pid());
    driver_before = driver_cpu_s();
  });
  asio::steady_timer at_end(io);
  at_end.expires_at(window.end);
  at_end.async_wait([&](std::error_code) {
    const ProcSample after = sample(mock.pid());
    const double s = ms_between(window.start, window.end) / 1000;
    r.cpu_cores = (after.cpu_s - before.cpu_s) / s;
    r.waited_fraction = (after.run_delay_s - before.run_delay_s) / s;
    r.driver_cpu_cores = (driver_cpu_s() - driver_before) / s;
    r.rss_kib = after.rss_kib;
    r.fds = after.fds;
    for (auto& c : clients)
      c->stop();
    echo_client->stop();
  });
  io.run();
  r.stat_expected = static_cast<double>(count) * o.seconds * 1000 / kStatPeriodMs;
  r.load_after = loadavg();
  mock.stop();
  std::filesystem::remove_all(dir);
  return r;
}

// ------------------------------------------------------------------ output

std::string fixed(double v, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

std::string table(const std::vector<Result>& results, double rate_hz) {
  std::ostringstream out;
  out << "| cars | STAT jitter p50 / p99 / max | STATs read | feedback p50 / p99 | echo p50 / p99 "
         "| mock CPU (cores) | mock waited for a core | CPU per car | RSS per car | mock fds | "
         "loadavg (before -> after) "
         "| breaks |\n"
      << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|\n";
  for (const auto& r : results) {
    if (!r.failure.empty()) {
      out << "| " << r.count << " | | | | | | | | | | " << r.load_before << " | " << r.failure
          << " |\n";
      continue;
    }
    const auto b = r.broken();
    std::string breaks;
    for (const auto& x : b)
      breaks += (breaks.empty() ? "" : ", ") + x;
    out << "| " << r.count << " | " << fixed(r.jitter_p50(), 2) << " / " << fixed(r.jitter_p99(), 2)
        << " / " << fixed(r.jitter_max(), 1) << " ms | " << r.m.stats << " of "
        << fixed(r.stat_expected, 0) << " | " << fixed(r.fb_p50(), 2) << " / "
        << fixed(r.fb_p99(), 2) << " ms | " << fixed(r.echo_p50(), 3) << " / "
        << fixed(r.echo_p99(), 3) << " ms | " << fixed(r.cpu_cores, 2) << " | "
        << fixed(r.waited_fraction * 100, 0) << " % | "
        << fixed(r.cpu_cores / static_cast<double>(r.count) * 1e6, 0) << " µs/s | "
        << fixed(r.kib_per_car(), 0) << " KiB | " << r.fds << " | " << r.load_before << " -> "
        << r.load_after << " | " << (breaks.empty() ? "none" : breaks) << " |\n";
  }
  (void)rate_hz;
  return out.str();
}

std::string details(const Result& r, const Options& o) {
  std::ostringstream out;
  out << r.count << " cars, " << o.seconds << " s measured, " << o.rate_hz
      << " command(s) per car per second (" << (o.parked ? "SP, parked" : "MV, spinning")
      << "): " << r.m.commands << " commands, " << r.m.feedback_ms.size() << " answered ("
      << r.m.rejected << " refused), " << r.m.feedback_missing << " without FB, " << r.m.bad_frames
      << " bad frames, " << r.m.connect_failures << " failed connects, " << r.m.disconnects
      << " dropped; " << r.m.echo_ms.size() << " echo round trips; load driver "
      << fixed(r.driver_cpu_cores, 2) << " cores; mock RSS " << fixed(r.rss_kib / 1024, 1)
      << " MiB (one-car mock " << fixed(r.baseline_rss_kib / 1024, 1) << " MiB)\n";
  return out.str();
}

std::vector<std::size_t> parse_list(const std::string& text) {
  std::vector<std::size_t> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) v.push_back(std::stoul(item));
  return v;
}

const char* const kUsage =
    "usage: fleet_load [--count N] [--seconds S] [--rate CMDS_PER_S] [--parked] "
    "[--hil PATH] "
    "[--sweep [N,N,...]] [--markdown FILE] [--max-ratio K --floor-ms F]\n";

/// The options on the command line; exits 2 on one it does not know, a
/// missing value, or a value out of range.
Options parse_options(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "fleet_load: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--count") {
      o.count = std::stoul(value());
    } else if (a == "--seconds") {
      o.seconds = std::stod(value());
    } else if (a == "--rate") {
      o.rate_hz = std::stod(value());
    } else if (a == "--parked") {
      o.parked = true;
    } else if (a == "--hil") {
      o.hil = value();
    } else if (a == "--sweep") {
      o.sweep = {250, 500, 1000, 1500, 2000, 3000, 4000, 6000};
      if (i + 1 < argc && argv[i + 1][0] != '-') o.sweep = parse_list(argv[++i]);
    } else if (a == "--markdown") {
      o.markdown = value();
    } else if (a == "--max-ratio") {
      o.max_ratio = std::stod(value());
    } else if (a == "--floor-ms") {
      o.floor_ms = std::stod(value());
    } else {
      std::cerr << kUsage;
      std::exit(2);
    }
  }
  if (o.count < 2 || o.seconds <= 0 || o.rate_hz <= 0 || o.rate_hz > 50) {
    std::cerr << "fleet_load: --count >= 2, --seconds > 0, --rate in (0, 50]\n";
    std::exit(2);
  }
  return o;
}

/// One fleet of --count cars, held to --max-ratio when asked; the exit
/// status (1 when the run failed or regressed).
int run_one(const Options& o, std::ostream& report) {
  const Result r = run_fleet(o, o.count);
  std::cerr << details(r, o);
  report << table({r}, o.rate_hz);
  if (!r.failure.empty()) {
    report << "\nThe run failed: " << r.failure << "\n";
    return 1;
  }
  if (!o.max_ratio) return 0;
  // The check: STAT jitter and feedback latency against the echo round
  // trip measured on the same loopback, in the same run.
  const double limit = *o.max_ratio * r.echo_p99() + o.floor_ms;
  report << "\nLimit: " << fixed(*o.max_ratio, 0) << " x echo p99 (" << fixed(r.echo_p99(), 3)
         << " ms) + " << fixed(o.floor_ms, 0) << " ms = " << fixed(limit, 2)
         << " ms for STAT jitter p99 and feedback p99.\n";
  if (r.jitter_p99() > limit || r.fb_p99() > limit || r.stat_lost_fraction() > 0.01 ||
      r.m.feedback_ms.empty() || r.m.disconnects > 0) {
    report << "REGRESSION: STAT jitter p99 " << fixed(r.jitter_p99(), 2) << " ms, feedback p99 "
           << fixed(r.fb_p99(), 2) << " ms, " << fixed(r.stat_lost_fraction() * 100, 1)
           << " % STATs missing, " << r.m.disconnects << " dropped\n";
    return 1;
  }
  return 0;
}

/// The fleet sizes of --sweep. A shared machine can break one size by a
/// blip of load: the sweep goes on past a broken target until the mock's
/// thread saturates (larger fleets only fall further behind) or a mock
/// cannot start, and names the first size at which each target broke.
void run_sweep(const Options& o, std::ostream& report) {
  std::vector<Result> results;
  std::vector<std::pair<std::string, std::size_t>> first_breaks;
  for (const auto n : o.sweep) {
    std::cerr << "fleet_load: " << n << " cars ..." << std::endl;
    results.push_back(run_fleet(o, n));
    std::cerr << details(results.back(), o);
    const auto b = results.back().broken();
    for (const auto& what : b)
      if (std::none_of(first_breaks.begin(), first_breaks.end(),
                       [&](const auto& f) { return f.first == what; }))
        first_breaks.emplace_back(what, n);
    if (!results.back().failure.empty() || results.back().cpu_cores >= kCpuSaturatedCores) break;
  }
  report << table(results, o.rate_hz) << '\n';
  if (first_breaks.empty()) {
    report << "No target broke up to " << o.sweep.back() << " cars.\n";
    return;
  }
  report << "First to break: " << first_breaks.front().first << " at "
         << first_breaks.front().second << " cars";
  for (std::size_t k = 1; k < first_breaks.size(); ++k)
    report << (k == 1 ? "; then " : ", ") << first_breaks[k].first << " at "
           << first_breaks[k].second;
  report << ".\n";
}

}  // namespace
}  // namespace hil::bench::fleet

int main(int argc, char** argv) {
  using namespace hil::bench::fleet;
  const Options o = parse_options(argc, argv);
  raise_fd_limit();
  std::signal(SIGPIPE, SIG_IGN);

  std::ostringstream report;
  report << "Measured on " << std::thread::hardware_concurrency() << " core(s), " << cpu_name()
         << ", with `fleet_load";
  for (int i = 1; i < argc; ++i)
    report << ' ' << argv[i];
  report << "`:\n\n";
  int exit_code = 0;
  if (o.sweep.empty())
    exit_code = run_one(o, report);
  else
    run_sweep(o, report);
  std::cout << report.str();
  if (!o.markdown.empty()) std::ofstream(o.markdown, std::ios::app) << report.str() << '\n';
  return exit_code;
}
