#pragma once
// What one run of one scenario came to: each step and each expectation with
// its verdict and evidence, the timeline, and the command that repeats it.
// The console table, JUnit XML and the report folder are written from this.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "harness/scenario.hpp"
#include "harness/timeline.hpp"
#include "sim/arena.hpp"
#include "sim/trajectory.hpp"

namespace hil::harness {

struct StepOutcome {
  int line = 0;
  std::string text;
  std::string phase;  ///< "setup", "steps", "teardown" or "schedule"
  bool ok = true;
  std::string reason;  ///< why it failed, for a person
  /// False when the step never started (an earlier step failed, the run
  /// timed out, or a scheduled step's moment never came); `reason` says which.
  bool ran = true;
  Time started{0};
  Time ended{0};
};

struct ExpectationOutcome {
  int line = 0;
  std::string label;
  bool passed = false;
  /// For a person: what was looked for, where, and what was found instead
  /// ("no 'car received MV:STOP' between 5.000 s and 5.300 s; the nearest
  /// at 5.812 s").
  std::string message;
  std::optional<Time> window_from;
  std::optional<Time> window_to;
  /// Records around the verdict (the matches, or what came closest and
  /// the frames near the window), in time order.
  std::vector<Record> evidence;

  /// "expect line 31", or "at the end" for what every run expects without
  /// a line of its own (an external program's clean exit, the car at rest).
  std::string where() const;
};

struct ScenarioOutcome {
  std::string file;
  std::string name;
  std::vector<std::string> tags;
  std::uint64_t seed = 0;
  /// Could not load or could not start (a bad file, a client that would not
  /// start): the whole scenario failed for this reason before any verdict.
  std::string error;
  std::vector<StepOutcome> steps;
  std::vector<ExpectationOutcome> expectations;
  Timeline timeline;
  sim::Arena arena;  ///< for the trajectory picture
  std::vector<sim::Trajectory> trajectories;
  Duration run_time{0};  ///< simulated (or real) time the run covered
  /// Where the session ended and the run stopped the client; what came
  /// after (its stop, the car judged at the end) is not judged by the
  /// scenario's expectations.
  Time session_end{0};
  double wall_seconds = 0;  ///< what it cost
  bool real_time = false;
  /// The command line that repeats this run exactly (seed included).
  std::string repro_command;
  /// The NDJSON wire log of the run (every byte each way, before and
  /// after the faults), when RunOptions::work_dir asked for one.
  std::string wire_log;

  /// Why the scenario was not run (see skip_reason() in harness/runner.hpp);
  /// empty: it ran.
  std::string skipped;

  /// Nothing failed: skipped, or run with no error, every step ok and
  /// every expectation met.
  bool passed() const;
  bool was_skipped() const { return !skipped.empty(); }
  /// The first thing that failed, for the table: "step 4 (press FWD): ..."
  /// or "expect line 31: ...", or the error; empty when passed.
  std::string first_failure() const;
};

}  // namespace hil::harness
