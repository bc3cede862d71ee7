#include "harness/judging.hpp"

#include <algorithm>
#include <utility>

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

}  // namespace

Duration time_slack(const RunOptions& options, bool real_time) {
  if (options.time_slack) return *options.time_slack;
  return real_time ? kRealTimeSlack : Duration(0);
}

std::vector<ExpectationOutcome> judge(const JudgedRun& run) {
  auto expectations = run.scenario.expectations;
  // Unless the scenario says what an external program's exit should be, a
  // clean one.
  if (run.external && std::none_of(expectations.begin(), expectations.end(), judges_exit))
    expectations.push_back(clean_exit(run));
  std::vector<ExpectationOutcome> outcomes;
  // An expectation on the exit looks past the session's end, where the exit is.
  for (const auto& e : expectations)
    outcomes.push_back(
        check(e, run.timeline, judges_exit(e) ? run.run_end : run.session_end, run.slack));
  return outcomes;
}

}  // namespace hil::harness
