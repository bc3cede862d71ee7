#pragma once
// What the Google Benchmark programs keep of a run: per benchmark its best
// repetition (the one least disturbed by other load on the machine) with
// its counters, and the floors CTest holds the figures to.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace hil::bench {

/// The best repetition of one benchmark.
struct BestRun {
  double seconds = 0;  ///< per iteration, on the reporter's clock
  std::map<std::string, double> counters;

  /// The counter `name`, 0 when the benchmark has none.
  double counter(const std::string& name) const {
    const auto it = counters.find(name);
    return it == counters.end() ? 0.0 : it->second;
  }
};

/// Google Benchmark's console output, and per benchmark the repetition
/// that took least time per iteration: CPU time (what waiting for a core
/// does not inflate), or wall time for benchmarks that wait themselves.
class BestRunReporter : public benchmark::ConsoleReporter {
 public:
  enum class Clock { cpu, wall };
  explicit BestRunReporter(Clock clock = Clock::cpu) : clock_(clock) {}

  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& run : runs) {
      if (run.error_occurred) failed_ = true;
      if (run.run_type != Run::RT_Iteration || run.iterations == 0) continue;
      const double total =
          clock_ == Clock::cpu ? run.cpu_accumulated_time : run.real_accumulated_time;
      const double seconds = total / static_cast<double>(run.iterations);
      auto [it, inserted] = best_.emplace(run.benchmark_name(), BestRun{});
      if (!inserted && seconds >= it->second.seconds) continue;
      it->second.seconds = seconds;
      it->second.counters.clear();
      for (const auto& [name, counter] : run.counters)
        it->second.counters[name] = counter.value;
    }
    ConsoleReporter::ReportRuns(runs);
  }

  /// Whether a benchmark reported an error (skipped with one).
  bool failed() const { return failed_; }

  /// True when no benchmark reported an error; else says so and is false.
  bool no_errors() const {
    if (failed_) std::printf("a benchmark reported an error (see above)\n");
    return !failed_;
  }

  /// The best repetition of `name`, nullptr when it did not run.
  const BestRun* best(const std::string& name) const {
    const auto it = best_.find(name);
    return it == best_.end() ? nullptr : &it->second;
  }

  /// Seconds per iteration of `name`'s best repetition, 0 when it did not run.
  double seconds(const std::string& name) const {
    const BestRun* b = best(name);
    return b == nullptr ? 0.0 : b->seconds;
  }

  /// Every benchmark that ran, by name.
  const std::map<std::string, BestRun>& all() const { return best_; }

 private:
  Clock clock_;
  std::map<std::string, BestRun> best_;
  bool failed_ = false;
};

/// --hil_min_ratio: `name`'s rate over `baseline`'s, in `unit` ("steps per
/// second"), must be at least `floor`. Prints the verdict; false, saying
/// so, when either did not run (a rate of 0).
inline bool check_ratio_floor(const char* name, double rate, const char* baseline,
                              double baseline_rate, const char* unit, double floor) {
  if (rate <= 0 || baseline_rate <= 0) {
    std::printf("--hil_min_ratio needs both %s and %s in the run\n", name, baseline);
    return false;
  }
  const bool pass = rate / baseline_rate >= floor;
  std::printf("%s / %s %s = %.2f (floor %.2f) %s\n", name, baseline, unit, rate / baseline_rate,
              floor, pass ? "ok" : "TOO SLOW");
  return pass;
}

/// --hil_min_realtime: `name` must run at least `floor` times faster than
/// real time. Prints the verdict; false, saying so, when it did not run (a
/// speed of 0).
inline bool check_realtime_floor(const std::string& name, double realtime_x, double floor) {
  if (realtime_x <= 0) {
    std::printf("--hil_min_realtime needs %s in the run\n", name.c_str());
    return false;
  }
  const bool pass = realtime_x >= floor;
  std::printf("%s runs %.0fx real time (floor %.0fx) %s\n", name.c_str(), realtime_x, floor,
              pass ? "ok" : "TOO SLOW");
  return pass;
}

}  // namespace hil::bench
