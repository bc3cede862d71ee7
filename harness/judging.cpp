#include "harness/judging.hpp"

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>

#include "base/duration.hpp"
#include "harness/expect.hpp"

namespace hil::harness {
namespace {

bool judges_exit(const Expectation& e) {
  return e.what.source == Source::client && e.what.kind == ClientKind::exit;
}

Expectation clean_exit(const JudgedRun& run) {
  Expectation exit;
  exit.label = "the client exited with code 0 after its input closed";
  exit.window.from.offset = run.session_end - Time(0);
  exit.window.within = run.run_end - run.session_end;
  exit.what = Matcher{Source::client,
                      ClientKind::exit,
                      {FieldTest{"code", FieldTest::Op::equals, 0}},
                      "client exit 0"};
  return exit;
}

std::string speed_text(double mps) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f m/s", mps);
  return buffer;
}

// The car at the end of the run against the scenario's `at_end`.
ExpectationOutcome end_outcome(const JudgedRun& run, const EndMotion& end) {
  const bool moving = end.moving || end.driven;
  const std::string after = hil::seconds_text(end.after, 1) + " after " +
                            (run.external ? "the client exited" : "the run stopped the client");
  std::string state = speed_text(end.speed_mps);
  if (end.driven) state += end.moving ? ", its motors driven" : ", but its motors still driven";
  ExpectationOutcome o;
  const bool wants_moving = run.scenario.at_end == AtEnd::moving;
  o.label = wants_moving ? "the car still moving " + after : "the car at rest " + after;
  o.passed = moving == wants_moving;
  if (wants_moving) {
    o.message =
        moving
            ? "the car was still moving " + after + " (" + state + "), as `at_end: moving` asks"
            : "expected the car still moving " + after + " (`at_end: moving`), but it was at rest";
  } else if (moving) {
    o.message = "the car was still moving " + after + " (" + state + "): " +
                (run.external ? "a client stops the car when its input ends "
                                "(docs/client-contract.md, section 4)"
                              : "the reference client stops the car when the run ends, as an "
                                "operator quitting does") +
                "; a scenario that ends moving on purpose says `at_end: moving`";
  } else {
    o.message = "the car was at rest " + after;
  }
  o.window_from = end.looked_at - end.after;
  o.window_to = end.looked_at;
  return o;
}

}  // namespace

Duration time_slack(const RunOptions& options, bool real_time, bool emulated_board) {
  if (options.time_slack) return *options.time_slack;
  if (real_time) return kRealTimeSlack;
  return emulated_board ? kEmulatedBoardSlack : Duration(0);
}

std::vector<ExpectationOutcome> judge(const JudgedRun& run) {
  const auto& expectations = run.scenario.expectations;
  // The session's records: the client's stop, even in the instant it
  // ended, is judged by the exit and the car's state at the end.
  Timeline session;
  const auto& records = run.timeline.records();
  for (std::size_t i = 0; i < std::min(run.session_records, records.size()); ++i)
    session.add(records[i]);
  std::vector<ExpectationOutcome> outcomes;
  // An expectation on the exit looks past the session's end, where the exit is.
  for (const auto& e : expectations)
    outcomes.push_back(judges_exit(e) ? check(e, run.timeline, run.run_end, run.slack, run.origin)
                                      : check(e, session, run.session_end, run.slack, run.origin));
  // Unless the scenario says what an external program's exit should be, a
  // clean one, between the session's end and the run's (times of the run,
  // not from the origin).
  if (run.external && std::none_of(expectations.begin(), expectations.end(), judges_exit))
    outcomes.push_back(check(clean_exit(run), run.timeline, run.run_end, run.slack));
  if (run.end && run.scenario.at_end != AtEnd::any) outcomes.push_back(end_outcome(run, *run.end));
  return outcomes;
}

}  // namespace hil::harness
