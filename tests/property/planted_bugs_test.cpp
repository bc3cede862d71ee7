// The LOGI properties have teeth: each known bug, planted in the client on
// its own through PlantedBugCore (tests/property/planted_bug.hpp), makes at
// least one named property fail within a fixed number of random sessions,
// and the same property passes on the same sessions without the bug.

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/detail/Configuration.h>

#include <algorithm>
#include <sstream>
#include <string>

#include "tests/property/logi_rig.hpp"

namespace hil::client::logi::prop {
namespace {

struct Case {
  const char* name;
  PlantedBug bug;
  Prop catcher;
};

// One fixed seed, so a run here is the same every time; enough sessions for
// every bug to show (each is found within the first few dozen).
constexpr std::uint64_t kSeed = 20261122;
constexpr int kSessions = 100;

// Sessions for the run without a bug: kSessions, or fewer when RC_PARAMS
// asks for fewer cases per property (the sanitizer trees run 25). The run
// with the bug keeps kSessions, since it ends at its first failing session.
int clean_sessions() {
  return std::min(kSessions, rc::detail::configuration().testParams.maxSuccess);
}

rc::detail::TestResult run(Prop p, PlantedBug bug, int sessions) {
  rc::detail::TestParams params;
  params.seed = kSeed;
  params.maxSuccess = sessions;
  params.maxSize = 100;
  params.disableShrinking = true;  // the verdict is what matters, not the smallest case
  rc::detail::TestMetadata metadata;
  metadata.id = std::string("planted/") + name_of(p);
  metadata.description = name_of(p);
  return rc::detail::checkTestable([p, bug] { run_property(p, bug); }, metadata, params);
}

std::string message(const rc::detail::TestResult& r) {
  std::ostringstream os;
  rc::detail::printResultMessage(r, os);
  return os.str();
}

class PlantedBugs : public ::testing::TestWithParam<Case> {};

TEST_P(PlantedBugs, IsCaughtByItsPropertyWhichPassesWithoutIt) {
  const Case& c = GetParam();
  const auto with_bug = run(c.catcher, c.bug, kSessions);
  EXPECT_TRUE(with_bug.template is<rc::detail::FailureResult>())
      << name_of(c.catcher) << " did not catch the planted bug " << c.name << ":\n"
      << message(with_bug);
  const auto without = run(c.catcher, PlantedBug::none, clean_sessions());
  EXPECT_TRUE(without.template is<rc::detail::SuccessResult>())
      << name_of(c.catcher) << " fails without any planted bug:\n"
      << message(without);
}

INSTANTIATE_TEST_SUITE_P(
    Logi, PlantedBugs,
    ::testing::Values(
        Case{"NoBackoff", PlantedBug::no_backoff, Prop::backoff_delays},
        Case{"RetryingStRun", PlantedBug::retry_run, Prop::retry_rules},
        Case{"NoMvStopOnRelease", PlantedBug::no_stop_on_release, Prop::stop_on_release},
        Case{"OneReadTakenAsOneFrame", PlantedBug::read_is_frame, Prop::stream_gives_every_frame},
        Case{"StaleAt5s", PlantedBug::stale_at_5s, Prop::stale_after_2s},
        Case{"NoSpRetry", PlantedBug::no_sp_retry, Prop::retry_rules},
        Case{"StStopBeforeMvStop", PlantedBug::st_stop_first, Prop::emergency_stop_order},
        // The end-to-end property sees a missing stop too: the car drives on.
        Case{"NoMvStopOnReleaseLeavesTheCarMoving", PlantedBug::no_stop_on_release,
             Prop::chassis_rests_after_stop}),
    [](const ::testing::TestParamInfo<Case>& param) { return std::string(param.param.name); });

}  // namespace
}  // namespace hil::client::logi::prop
