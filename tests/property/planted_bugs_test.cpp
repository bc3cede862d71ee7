// The LOGI properties have teeth: each known bug, planted in the client on
// its own through PlantedBugCore (tests/property/planted_bug.hpp), makes at
// least one named property fail within a fixed number of random sessions,
// and the same property passes on the same sessions without the bug.

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/detail/Configuration.h>

#include <algorithm>
#include <ostream>
#include <sstream>
#include <string>

#include "tests/property/logi_rig.hpp"
#include "tests/property/planted_check.hpp"

namespace hil::client::logi::prop {
namespace {

struct Case {
  const char* name;
  PlantedBug bug;
  Prop catcher;
};

rc::detail::TestResult run(Prop p, PlantedBug bug, int sessions) {
  return run_planted(name_of(p), sessions, [p, bug] { run_property(p, bug); });
}

// The case's name in CTest's name for it, instead of its bytes.
void PrintTo(const Case& c, std::ostream* os) {
  *os << c.name;
}

class PlantedBugs : public ::testing::TestWithParam<Case> {};

TEST_P(PlantedBugs, IsCaughtByItsPropertyWhichPassesWithoutIt) {
  const Case& c = GetParam();
  expect_caught_and_clean(name_of(c.catcher), c.name, [&c](bool planted, int sessions) {
    return run(c.catcher, planted ? c.bug : PlantedBug::none, sessions);
  });
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
        Case{"EmergencyStStopSentOnce", PlantedBug::st_stop_once, Prop::estop_st_stop_resent},
        // End to end: a lost ST:STOP that is never written again leaves an auto run going.
        Case{"EmergencyStStopSentOnceLeavesTheCarRunning", PlantedBug::st_stop_once,
             Prop::car_rests_after_estop},
        Case{"NoMvStopAfterAMoveTimedOut", PlantedBug::no_stop_after_move_timeout,
             Prop::move_timeout_stops},
        Case{"StaleAtExactly2s", PlantedBug::stale_at_2s, Prop::stale_after_2s},
        Case{"AnyFrameClearsStale", PlantedBug::any_frame_clears_stale, Prop::stale_after_2s},
        // The end-to-end property sees a missing stop too: the car drives on.
        Case{"NoMvStopOnReleaseLeavesTheCarMoving", PlantedBug::no_stop_on_release,
             Prop::chassis_rests_after_stop}),
    [](const ::testing::TestParamInfo<Case>& param) { return std::string(param.param.name); });

}  // namespace
}  // namespace hil::client::logi::prop
