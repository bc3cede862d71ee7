// Random client sessions in virtual time: how many random LOGI sessions of
// 60 simulated seconds each one core runs per second, physics included, as
// the property tests run them (target: at least 20 per second). Besides
// Google Benchmark's own flags:
//   --hil_markdown=FILE          writes the result as a Markdown table;
//   --hil_min_sessions_per_s=X   exit 1 unless the rate is at least X.
// Each iteration is one whole session from scratch, different every time
// (its seed is the iteration number): a fresh LOGI mock car (world, arena,
// mecanum chassis, firmware) behind a MockServer on mem:// with a random
// fault profile, the reference client (client::logi::LogiSession) connected
// to it, and random operator actions (speed, mode, directions pressed and
// released, stations, run, stop, emergency stop, disconnect and connect)
// spread over 60 s of virtual time. Rates are from the benchmark thread's CPU
// time, so time spent waiting for a core on a busy machine does not count;
// with --benchmark_repetitions the best repetition counts.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "bench/best_runs.hpp"
#include "bench/hil_flags.hpp"
#include "client/logi/session.hpp"
#include "link/faults/profile.hpp"
#include "link/transport.hpp"
#include "mocks/car.hpp"
#include "mocks/server.hpp"

namespace {

namespace link = hil::link;
namespace mocks = hil::mocks;
namespace logi = hil::client::logi;
namespace proto = hil::protocol::logi;

using link::Duration;
using link::milliseconds;
using link::seconds;
using link::Time;

constexpr Duration kSession = seconds(60);

using Rng = std::mt19937_64;

int uniform(Rng& rng, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(rng);
}
bool chance(Rng& rng, double p) {
  return std::bernoulli_distribution(p)(rng);
}

// What a property test draws: each kind of fault present or not, at a
// random rate, in a random direction; timed stalls and resets.
link::FaultProfile random_faults(Rng& rng) {
  link::FaultProfile profile;
  auto add = [&](link::FaultAction action) {
    link::FaultRule rule;
    rule.direction = static_cast<link::DirectionFilter>(uniform(rng, 0, 2));
    rule.trigger.probability = uniform(rng, 1, 20) / 100.0;
    rule.action = std::move(action);
    profile.rules.push_back(std::move(rule));
  };
  auto add_timed = [&](link::FaultAction action) {
    link::FaultRule rule;
    rule.trigger.at = milliseconds(uniform(rng, 0, 60'000));
    rule.action = std::move(action);
    profile.rules.push_back(std::move(rule));
  };
  if (chance(rng, 0.5)) add(link::Drop{});
  if (chance(rng, 0.5)) add(link::Corrupt{link::CorruptTarget::checksum, {}, 1});
  if (chance(rng, 0.5)) add(link::Duplicate{1});
  if (chance(rng, 0.5))
    add(link::Delay{milliseconds(uniform(rng, 0, 300)), milliseconds(uniform(rng, 0, 300))});
  if (chance(rng, 0.5))
    add(link::Fragment{{1, 8}, {Duration{0}, milliseconds(uniform(rng, 0, 20))}});
  if (chance(rng, 0.5)) add(link::Coalesce{3, milliseconds(uniform(rng, 1, 100))});
  for (int i = uniform(rng, 0, 2); i > 0; --i)
    add_timed(link::Stall{milliseconds(uniform(rng, 100, 4000))});
  for (int i = uniform(rng, 0, 2); i > 0; --i)
    add_timed(link::Reset{});
  link::validate(profile);
  return profile;
}

proto::Direction random_direction(Rng& rng) {
  return static_cast<proto::Direction>(uniform(rng, 1, 10));  // any but stop
}

/// One operator action; true when it was a disconnect (the operator connects
/// again with the next action).
bool random_action(Rng& rng, logi::LogiSession& session) {
  switch (uniform(rng, 0, 10)) {
    case 0:
      session.submit(proto::SetSpeed{uniform(rng, 0, 100)});
      break;
    case 1:
      session.submit(
          proto::SetMode{chance(rng, 0.5) ? proto::Mode::manual : proto::Mode::automatic});
      break;
    case 2:
    case 3:
      session.press(random_direction(rng));
      break;
    case 4:
    case 5:
      session.release();
      break;
    case 6:
      session.submit(proto::SetStation{uniform(rng, 1, 2)});
      break;
    case 7:
      session.submit(proto::SetRun{true});
      break;
    case 8:
      session.submit(proto::SetRun{false});
      break;
    case 9:
      session.emergency_stop();
      break;
    default:
      session.disconnect();
      return true;
  }
  return false;
}

struct SessionResult {
  std::uint64_t events = 0;         ///< what the client reported to its UI
  std::uint64_t status_frames = 0;  ///< STATs the client decoded
  std::uint64_t actions = 0;
  std::uint64_t faults = 0;
};

SessionResult run_session(std::uint64_t seed) {
  Rng rng(seed);
  link::VirtualExecutor executor;  // first: everything below schedules on it
  link::TransportContext context{executor};
  mocks::CarOptions car_options;
  car_options.kind = mocks::CarKind::logi;
  car_options.seed = seed;
  mocks::MockCar car(car_options);
  mocks::ServerOptions server_options;
  server_options.listen = link::MemEndpoint{"car"};
  server_options.seed = seed;
  server_options.faults = random_faults(rng);
  mocks::MockServer server(context, car.firmware(), server_options);
  server.start();

  SessionResult result;
  logi::LogiSession session(context, link::MemEndpoint{"car"}, {},
                            [&result](Time, const logi::Event& e) {
                              ++result.events;
                              if (std::holds_alternative<logi::StatusEvent>(e))
                                ++result.status_frames;
                            });
  session.connect();
  Time at{0};
  bool disconnected = false;
  while (true) {
    at += milliseconds(uniform(rng, 100, 3000));
    if (at >= kSession) break;
    executor.run_until(at);
    if (disconnected) {
      session.connect();
      disconnected = false;
    } else {
      disconnected = random_action(rng, session);
    }
    ++result.actions;
  }
  executor.run_until(Time(kSession));
  result.faults = server.faults_injected();
  session.disconnect();
  executor.run_for(Duration::zero());
  server.close();
  return result;
}

void random_sessions(benchmark::State& state) {
  double status_frames = 0;
  double actions = 0;
  double faults = 0;
  double events = 0;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    const SessionResult r = run_session(seed++);
    status_frames += static_cast<double>(r.status_frames);
    actions += static_cast<double>(r.actions);
    faults += static_cast<double>(r.faults);
    events += static_cast<double>(r.events);
  }
  // A session that saw almost no telemetry did not run the car: time nothing.
  if (state.iterations() > 0 && status_frames / static_cast<double>(state.iterations()) < 20)
    state.SkipWithError("the client decoded under 20 STATs per 60 s session");
  using benchmark::Counter;
  state.counters["sessions_per_s"] = Counter(1, Counter::kIsIterationInvariantRate);
  state.counters["stat_frames"] = Counter(status_frames, Counter::kAvgIterations);
  state.counters["actions"] = Counter(actions, Counter::kAvgIterations);
  state.counters["faults"] = Counter(faults, Counter::kAvgIterations);
  state.counters["events"] = Counter(events, Counter::kAvgIterations);
}

constexpr const char* kSessionBenchmark = "logi_random_session";

class RecordingReporter : public hil::bench::BestRunReporter {
 public:
  bool check(double min_rate) const {
    if (failed()) {
      std::printf("the benchmark reported an error (see above)\n");
      return false;
    }
    const double cpu_s = seconds(kSessionBenchmark);
    if (min_rate <= 0 || cpu_s <= 0) return true;
    const double rate = 1 / cpu_s;
    const bool pass = rate >= min_rate;
    std::printf("random LOGI sessions: %.1f per CPU second (floor %.1f) %s\n", rate, min_rate,
                pass ? "ok" : "TOO SLOW");
    return pass;
  }

  void write_markdown(const std::string& path) const {
    const hil::bench::BestRun* b = best(kSessionBenchmark);
    if (b == nullptr || b->seconds <= 0) return;
    const double cpu_s = b->seconds;
    std::ofstream out(path);
    char line[512];
    out << "| sessions per CPU second | ms CPU per 60 s session | x real time | "
           "operator actions / faults injected / STATs decoded / client events per session |\n"
           "|---:|---:|---:|---:|\n";
    std::snprintf(line, sizeof line, "| %.1f | %.2f | %.0f | %.0f / %.0f / %.0f / %.0f |\n",
                  1 / cpu_s, cpu_s * 1e3, 60 / cpu_s, b->counter("actions"), b->counter("faults"),
                  b->counter("stat_frames"), b->counter("events"));
    out << line;
    std::snprintf(line, sizeof line,
                  "\n%.1f random sessions of 60 simulated seconds per second "
                  "on one core (target >= 20).\n",
                  1 / cpu_s);
    out << line;
  }
};

}  // namespace

int main(int argc, char** argv) {
  auto flags = hil::bench::take_hil_flags(argc, argv);
  benchmark::RegisterBenchmark(kSessionBenchmark, random_sessions)->Unit(benchmark::kMillisecond);
  RecordingReporter reporter;
  return hil::bench::run_and_check(
      flags, reporter, [&] { return reporter.check(flags.number("min_sessions_per_s")); });
}
