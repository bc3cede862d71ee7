// Virtual-time speed of the whole stack: a LOGI auto tour through a faulty
// link (bench/scenarios/logi-auto-tour-long.yaml: the reference client, the
// mock car with its firmware and physics, the link with its faults, the
// timeline and the expectations) run by the scenario runner exactly as
// `hil run` runs it, against bare Box2D stepping the same bodies the same
// number of steps in the same run. Besides Google Benchmark's own flags:
//   --hil_scenario=FILE     times this scenario instead (a virtual-time one);
//   --hil_markdown=FILE     writes the results as a Markdown table;
//   --hil_min_ratio=R       exit 1 unless the stack runs at least R times as
//                           many simulated seconds per CPU second as bare
//                           Box2D;
//   --hil_min_realtime=X    exit 1 unless the stack runs at least X times
//                           faster than real time.
// Each iteration is one whole run from scratch. Rates are from the benchmark
// thread's CPU time, so time spent waiting for a core on a busy machine does
// not count; with --benchmark_repetitions the best repetition of each counts.
// A run that does not pass (a car that never reaches its stations, a fault
// that never fired) fails the benchmark instead of timing a stuck car.

#include <benchmark/benchmark.h>
#include <box2d/box2d.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "bench/bare_box2d.hpp"
#include "bench/best_runs.hpp"
#include "bench/hil_flags.hpp"
#include "harness/runner.hpp"
#include "harness/scenario_yaml.hpp"
#include "sim/arena.hpp"
#include "sim/presets.hpp"
#include "sim/time.hpp"

namespace {

using hil::sim::kStepSeconds;
using hil::sim::kStepsPerSecond;

constexpr const char* kStack = "stack";
constexpr const char* kBare = "bare_box2d";
// For a scenario file without a seed of its own, so every run covers the
// same simulated time.
constexpr std::uint64_t kSeedWhenTheFileHasNone = 1;

struct Subject {
  hil::harness::Scenario scenario;
  double run_s = 0;  // simulated seconds one run covers (the same every run: seeded)
  std::int64_t steps = 0;
};

Subject& subject() {
  static Subject s;
  return s;
}

hil::harness::RunOptions run_options() {
  hil::harness::RunOptions options;
  if (!subject().scenario.seed) options.seed = kSeedWhenTheFileHasNone;
  return options;
}

void stack(benchmark::State& state) {
  const Subject& s = subject();
  for (auto _ : state) {
    const auto outcome = hil::harness::run_scenario(s.scenario, run_options());
    if (!outcome.passed()) {
      state.SkipWithError(("the scenario failed: " + outcome.first_failure()).c_str());
      return;
    }
    benchmark::DoNotOptimize(outcome.timeline);
  }
}

// The arena World::build_arena makes for the built-in warehouse (four walls,
// the shelf, the pillar) and the LOGI car's body, with no hil code in the
// loop: the car drives a circle in the free floor left of the shelf, its
// velocity set before every step as Vehicle does, for as many fixed steps
// as the scenario's run takes. A fresh world each run, as the runner builds.
void bare_box2d(benchmark::State& state) {
  const hil::sim::Arena arena = hil::sim::default_warehouse_arena();
  const hil::sim::MecanumDef car;
  const std::int64_t steps = subject().steps;
  constexpr double kSpeed_mps = 0.3;
  constexpr double kTurnRate_radps = 1.0;  // a 0.3 m circle
  double end_x = 0;
  for (auto _ : state) {
    // On the heap: b2World carries Box2D's 100 KiB stack allocator.
    const auto world = std::make_unique<b2World>(b2Vec2(0.0f, 0.0f));
    hil::bench::add_bare_arena(*world, arena);
    b2Body* body = hil::bench::add_bare_car(*world, car, hil::sim::Pose{0.7, 0.7, 0.0});
    for (std::int64_t i = 0; i < steps; ++i) {
      const double angle = static_cast<double>(body->GetAngle());
      body->SetLinearVelocity(b2Vec2(static_cast<float>(kSpeed_mps * std::cos(angle)),
                                     static_cast<float>(kSpeed_mps * std::sin(angle))));
      body->SetAngularVelocity(static_cast<float>(kTurnRate_radps));
      world->Step(static_cast<float>(kStepSeconds), 8, 3);
    }
    end_x = static_cast<double>(body->GetPosition().x);
  }
  // The circle (centre (0.7, 1.0)) stays between x 0.4 and 1.0: a car held
  // by a wall or stopped somewhere else did not measure a moving car.
  if (!(end_x > 0.3 && end_x < 1.1)) state.SkipWithError("the bare car left its circle");
}

class RecordingReporter : public hil::bench::BestRunReporter {
 public:
  /// CPU seconds per run of the best repetition, 0 when it did not run.
  double cpu_s(const std::string& name) const { return seconds(name); }
  /// Simulated seconds per CPU second, 0 when it did not run.
  double realtime_x(const std::string& name) const {
    const double s = cpu_s(name);
    return s <= 0 ? 0.0 : subject().run_s / s;
  }

  bool check(double min_ratio, double min_realtime) const {
    bool ok = no_errors();
    const double full = realtime_x(kStack);
    if (min_ratio > 0) {
      ok = hil::bench::check_ratio_floor(kStack, full, kBare, realtime_x(kBare),
                                         "simulated seconds per CPU second", min_ratio) &&
           ok;
    }
    if (min_realtime > 0) ok = hil::bench::check_realtime_floor(kStack, full, min_realtime) && ok;
    return ok;
  }

  void write_markdown(const std::string& path) const {
    std::ofstream out(path);
    char line[320];
    const double bare = realtime_x(kBare);
    const double full = realtime_x(kStack);
    std::snprintf(line, sizeof line, "Each run: %s, %.2f simulated seconds, %lld fixed steps.\n\n",
                  subject().scenario.file.c_str(), subject().run_s,
                  static_cast<long long>(subject().steps));
    out << line;
    out << "| what runs | ms CPU per run | x real time | / bare Box2D |\n"
           "|---|---:|---:|---:|\n";
    const std::map<std::string, std::string> titles{
        {kStack, "the whole stack (`hil run`'s runner)"},
        {kBare, "bare Box2D, the same bodies and steps"}};
    for (const char* name : {kBare, kStack}) {
      const double rate = realtime_x(name);
      if (rate <= 0) continue;
      char ratio[16] = "-";
      if (bare > 0) std::snprintf(ratio, sizeof ratio, "%.2f", rate / bare);
      std::snprintf(line, sizeof line, "| %s | %.2f | %.0f | %s |\n", titles.at(name).c_str(),
                    cpu_s(name) * 1e3, rate, ratio);
      out << line;
    }
    if (full > 0 && bare > 0) {
      std::snprintf(line, sizeof line,
                    "\nThe whole stack: %.0fx real time (target >= 1000x), %.2f of the bare "
                    "Box2D rate (target >= 0.40).\n",
                    full, full / bare);
      out << line;
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  auto flags = hil::bench::take_hil_flags(argc, argv);
  std::string file = flags.text("scenario");
  if (file.empty()) file = HIL_SOURCE_DIR "/bench/scenarios/logi-auto-tour-long.yaml";
  Subject& s = subject();
  try {
    s.scenario = hil::harness::load_scenario(file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  // One run first: it must pass, and it says how long a run is in simulated
  // time, which the bare world then steps through.
  const auto first = hil::harness::run_scenario(s.scenario, run_options());
  if (!first.passed()) {
    std::fprintf(stderr, "%s does not pass, so there is nothing to time: %s\n", file.c_str(),
                 first.first_failure().c_str());
    return 1;
  }
  if (first.real_time) {
    std::fprintf(stderr, "%s runs in real time; only virtual-time runs are timed\n", file.c_str());
    return 2;
  }
  s.run_s = std::chrono::duration<double>(first.run_time).count();
  s.steps = static_cast<std::int64_t>(std::llround(s.run_s * kStepsPerSecond));

  benchmark::RegisterBenchmark(kBare, bare_box2d)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark(kStack, stack)->Unit(benchmark::kMillisecond);
  RecordingReporter reporter;
  return hil::bench::run_and_check(flags, reporter, [&] {
    return reporter.check(flags.number("min_ratio"), flags.number("min_realtime"));
  });
}
