// Each car's scenario library has teeth. Run whole in virtual time with
// hil's reference client for that car swapped, through
// RunOptions::reference_client, for the same client with one known bug
// planted in its core (tests/property/planted_bug.hpp for LOGI,
// wr8_planted_bug.hpp, arduino_planted_bug.hpp), the library fails, and
// among the scenarios that fail are the ones named below for the rule that
// bug breaks. With no bug planted, through the same seam, every scenario
// passes. One CTest test per car and bug ("wr8_no_backoff", "logi_none").

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "harness/client_under_test.hpp"
#include "harness/reference_client.hpp"
#include "harness/reference_settings.hpp"
#include "tests/gate/library_run.hpp"
#include "tests/property/arduino_planted_bug.hpp"
#include "tests/property/planted_bug.hpp"
#include "tests/property/wr8_planted_bug.hpp"

namespace hil::harness {
namespace {

namespace fs = std::filesystem;
namespace logi_bugs = client::logi::prop;
namespace wr8_bugs = client::wr8::prop;
namespace arduino_bugs = client::arduino::prop;

/// Bug name -> the scenarios written for the rule it breaks: each must
/// fail with the bug planted (the reason measured is noted, for the reader).
/// Others may fail too: a bug shows wherever its rule is in play.
using Catchers = std::map<std::string_view, std::vector<std::string>>;

const Catchers kLogiCatchers = {
    // 'client connecting' thousands of times at one instant instead of at
    // +1, +3, +6 ... s.
    {"no_backoff",
     {"logi-reconnect-series", "logi-connect-refused", "logi-reconnect-connection-loss"}},
    // `run` after an unanswered ST:RUN must fail as uncertain; resent, it
    // succeeds.
    {"retry_run", {"logi-run-uncertain-confirm"}},
    // `release` sends nothing, so the action never ends.
    {"no_stop_on_release", {"logi-buttons", "logi-manual-directions"}},
    // Frames split across reads are lost: commands get no feedback.
    {"read_is_frame", {"logi-buttons-fragmented", "logi-parser-mixed"}},
    // No stale warning 2 s after the last STAT.
    {"stale_at_5s", {"logi-telemetry-stale", "logi-telemetry-stale-stall"}},
    // SP sent once, not at +0, +0.8 and +1.6 s.
    {"no_sp_retry", {"logi-retry-sp-ignored", "logi-retry-sp-uncertain"}},
    // ST:STOP reaches the car before MV:STOP, not after it.
    {"st_stop_first", {"logi-estop-order-auto-run", "logi-estop-order-idle-sticky"}},
    // ST:STOP written once: the emergency stop is given up as uncertain.
    {"st_stop_once", {"logi-dod-estop-st-stop-resent", "logi-dod-estop-st-stop-lost-sticky"}},
    // No MV:STOP 800 ms after an unanswered MV:FWD.
    {"no_stop_after_move_timeout", {"logi-dod-move-timeout-stop"}},
    // The warning at exactly 2 s after the last STAT, not after it.
    {"stale_at_2s", {"logi-dod-stale-strict"}},
    // An FB while STAT is muted reported as fresh telemetry.
    {"any_frame_clears_stale",
     {"logi-stale-feedback-not-fresh", "logi-stale-feedback-not-fresh-driving",
      "logi-dod-stale-strict"}},
};

const Catchers kWr8Catchers = {
    // Logged in as the AUTH goes out: the login is reported at 0 s, not when
    // the AUTH-REPLY arrives (401 ms, 1.001 s), and the tasks go out before
    // it; a wrong string's connect succeeds.
    {"task_before_auth",
     {"wr8-auth-tasks-wait-for-reply", "wr8-auth-good", "wr8-auth-wrong-string"}},
    // A stray or late answer ends the drive under way: completed at 1.001 s
    // (0.702 s) instead of on its own answer at 3.331 s (3.831 s).
    {"newest_task_answer", {"wr8-task-unknown-coi-answer", "wr8-task-late-answer-ignored"}},
    // Attempts every time a connection fails instead of 1, 2, 4, 8 s later;
    // against a car that refuses, thousands at one instant.
    {"no_backoff", {"wr8-reconnect-backoff", "wr8-auth-bad-corrupt"}},
};

const Catchers kArduinoCatchers = {
    // V 160 fails with the board's NACK BAD_CS instead of being resent at
    // once; the damaged V goes out once, not four times.
    {"no_resend_on_bad_cs", {"arduino-nack-bad-cs-corrupt", "arduino-nack-bad-cs-exhausted"}},
    // A PONG with PING's SEQ, in while V waits, ends V before the board's
    // own answer to it.
    {"any_seq_is_answer", {"arduino-stale-reply-duplicate", "arduino-stale-reply-injected"}},
    // Attempts 0.6 s apart every time, not 0.6, 1.2, 2.4 s.
    {"fixed_timeout", {"arduino-retry-drop", "arduino-health-timeout-ignore"}},
};

nlohmann::json settings_of(const Scenario& scenario) {
  const auto* reference = std::get_if<ReferenceClient>(&scenario.client);
  return reference ? reference->settings : nlohmann::json::object();
}

// The reference client of `setup`'s scenario on a core with `bug`,
// configured as make_reference_client() configures the shipped one; null
// (hil's own client, which expect_whole_library_ran() then reports) for a
// scenario of another car or dialect.
std::unique_ptr<ScenarioClient> logi_client(logi_bugs::PlantedBug bug, const ClientSetup& setup) {
  if (setup.scenario.car != mocks::CarKind::logi) return nullptr;
  return make_logi_reference_client(setup.context, setup.car, setup.timeline,
                                    std::make_unique<logi_bugs::PlantedBugCore>(
                                        bug, logi_client_config(settings_of(setup.scenario))));
}

std::unique_ptr<ScenarioClient> wr8_client(wr8_bugs::PlantedBug bug, const ClientSetup& setup) {
  const Scenario& scenario = setup.scenario;
  // The planted bugs are in the document's dialect, which the library speaks.
  if (scenario.car != mocks::CarKind::wr8 || svgui_version(scenario.car, scenario.profile))
    return nullptr;
  return make_wr8_reference_client(
      setup.context, setup.car, setup.timeline,
      std::make_unique<wr8_bugs::PlantedBugCore>(bug, wr8_client_config(settings_of(scenario))));
}

std::unique_ptr<ScenarioClient> arduino_client(arduino_bugs::PlantedBug bug,
                                               const ClientSetup& setup) {
  const Scenario& scenario = setup.scenario;
  if (scenario.car != mocks::CarKind::arduino) return nullptr;
  return make_arduino_reference_client(
      setup.context, setup.car, setup.timeline,
      std::make_unique<arduino_bugs::PlantedBugCore>(
          bug, arduino_client_config(settings_of(scenario), scenario.profile)));
}

/// One run of a car's whole library: with one bug planted, or none.
struct LibraryCase {
  std::string car;
  std::string bug;  ///< "none": the client as shipped
  fs::path library;
  std::vector<std::string> catchers;
  gate::ClientFactory make;
};

// The bug's car and name in a failure's parameter line.
void PrintTo(const LibraryCase& c, std::ostream* os) {
  *os << c.car << " with " << c.bug;
}

// One case per entry of a car's planted-bug table (`none` among them).
template <class BugName, std::size_t N, class Make>
void add_cases(std::vector<LibraryCase>& cases, const std::string& car, const BugName (&bugs)[N],
               const Catchers& catchers, Make make) {
  for (const auto& b : bugs) {
    const auto named = catchers.find(b.name);
    cases.push_back(
        LibraryCase{car, std::string(b.name), fs::path(HIL_SOURCE_DIR) / "scenarios" / car,
                    named == catchers.end() ? std::vector<std::string>{} : named->second,
                    [make, bug = b.bug](const ClientSetup& setup) { return make(bug, setup); }});
  }
}

std::vector<LibraryCase> library_cases() {
  std::vector<LibraryCase> cases;
  add_cases(cases, "logi", logi_bugs::kPlantedBugs, kLogiCatchers, logi_client);
  add_cases(cases, "wr8", wr8_bugs::kPlantedBugs, kWr8Catchers, wr8_client);
  add_cases(cases, "arduino", arduino_bugs::kPlantedBugs, kArduinoCatchers, arduino_client);
  return cases;
}

class PlantedBugLibrary : public ::testing::TestWithParam<LibraryCase> {};

TEST_P(PlantedBugLibrary, FailsInTheScenariosOfTheRuleABugBreaksAndPassesWithNone) {
  const LibraryCase& c = GetParam();
  const gate::LibraryRun run = gate::run_library(c.library, c.make);
  gate::expect_whole_library_ran(c.library, run);
  if (c.bug == "none") {
    EXPECT_TRUE(run.failed.empty())
        << "the " << c.car
        << " client as shipped, made through the seam, failed:" << run.failures_text();
    return;
  }
  gate::expect_caught_by(c.library, run, c.bug, c.catchers);
}

INSTANTIATE_TEST_SUITE_P(Cars, PlantedBugLibrary, ::testing::ValuesIn(library_cases()),
                         [](const ::testing::TestParamInfo<LibraryCase>& info) {
                           return info.param.car + "_" + info.param.bug;
                         });

}  // namespace
}  // namespace hil::harness
