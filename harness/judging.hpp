#pragma once
// Judges a finished run: each of the scenario's expectations against the
// timeline, with an external program's clean exit expected unless the
// scenario says what its exit should be.

#include <optional>
#include <vector>

#include "harness/origin.hpp"
#include "harness/outcome.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"
#include "harness/timeline.hpp"

namespace hil::harness {

/// How the car was when the run looked at it, a while after the client
/// stopped (scenario `at_end`).
struct EndMotion {
  /// How long after the client stopped (an external program exited, or
  /// the run stopped its reference client) the car was looked at.
  Duration after{0};
  /// When it was looked at.
  Time looked_at{0};
  /// The chassis was not at rest (SimObserver's notion), at this speed.
  bool moving = false;
  double speed_mps = 0;
  /// The firmware still drove the motors (a car held by a wall moves not).
  bool driven = false;
};

struct JudgedRun {
  const Scenario& scenario;
  const Timeline& timeline;
  /// The client was an external program.
  bool external = false;
  /// Where the session ended (an external program's input closed, the
  /// reference client about to be stopped): the expectations judge up to
  /// here, except those on the program's exit.
  Time session_end{0};
  /// How many records the timeline had then: what stopping the client
  /// caused at that same instant is not part of the session.
  std::size_t session_records = 0;
  /// Where the run ended, after an external program's exit.
  Time run_end{0};
  /// Room for real time in every expectation (check() in harness/expect.hpp).
  Duration slack{0};
  /// Where the scenario's run times count from.
  Origin origin;
  /// How the car was at the end; nullopt: not looked at.
  std::optional<EndMotion> end;
};

/// The room for real time a run gets: RunOptions::time_slack, else
/// kRealTimeSlack in real time, kEmulatedBoardSlack for a real firmware on
/// the emulated board in virtual time, and none for a mock in virtual time.
Duration time_slack(const RunOptions& options, bool real_time, bool emulated_board);

/// One outcome per expectation, in the scenario's order, then the exit's,
/// then the car's at the end (unless the scenario says `at_end: any`).
std::vector<ExpectationOutcome> judge(const JudgedRun& run);

}  // namespace hil::harness
