#pragma once
// Judges a finished run: each of the scenario's expectations against the
// timeline, with an external program's clean exit expected unless the
// scenario says what its exit should be.

#include <vector>

#include "harness/outcome.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"
#include "harness/timeline.hpp"

namespace hil::harness {

struct JudgedRun {
  const Scenario& scenario;
  const Timeline& timeline;
  /// The client was an external program.
  bool external = false;
  /// Where the session ended (an external program's input closed): the
  /// expectations judge up to here, except those on the program's exit.
  Time session_end{0};
  /// Where the run ended, after an external program's exit.
  Time run_end{0};
  /// Room for real time in every expectation (check() in harness/expect.hpp).
  Duration slack{0};
};

/// The room for real time a run gets: RunOptions::time_slack, else
/// kRealTimeSlack in real time and none in virtual time.
Duration time_slack(const RunOptions& options, bool real_time);

/// One outcome per expectation, in the scenario's order, then the exit's.
std::vector<ExpectationOutcome> judge(const JudgedRun& run);

}  // namespace hil::harness
