#pragma once
// How a test shows that a property has teeth: the property run with a bug
// planted, from one fixed seed and without shrinking, must fail; run
// without it, it must pass. Shared by the LOGI client's planted bugs
// (planted_bugs_test.cpp), the terminal UI's (tui_model_properties_test.cpp)
// and the WR8 and Arduino clients' (their properties' test files).

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/detail/Configuration.h>

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>

namespace hil::client::logi::prop {

/// One fixed seed, so a run is the same every time; enough sessions for
/// every planted bug to show (each is found within the first few dozen).
inline constexpr std::uint64_t kPlantedSeed = 20261122;
inline constexpr int kPlantedSessions = 100;

/// Sessions for the run without a bug: kPlantedSessions, or fewer when
/// RC_PARAMS asks for fewer cases per property (the sanitizer trees run
/// 25). The run with the bug keeps kPlantedSessions, since it ends at its
/// first failing session.
inline int clean_sessions() {
  return std::min(kPlantedSessions, rc::detail::configuration().testParams.maxSuccess);
}

/// Runs `property` (a callable that checks one random session) `sessions`
/// times from kPlantedSeed, without shrinking; `id` names it in messages.
template <class Property>
rc::detail::TestResult run_planted(const std::string& id, int sessions, Property property) {
  rc::detail::TestParams params;
  params.seed = kPlantedSeed;
  params.maxSuccess = sessions;
  params.maxSize = 100;
  params.disableShrinking = true;  // the verdict is what matters, not the smallest case
  rc::detail::TestMetadata metadata;
  metadata.id = "planted/" + id;
  metadata.description = id;
  return rc::detail::checkTestable(std::move(property), metadata, params);
}

/// rapidcheck's own account of a result.
inline std::string result_message(const rc::detail::TestResult& r) {
  std::ostringstream os;
  rc::detail::printResultMessage(r, os);
  return os.str();
}

/// The verdict of one planted bug (gtest failures otherwise): `run(planted,
/// sessions)` runs the property `property` with the bug `bug` planted
/// (true) or none (false); with it the property fails within
/// kPlantedSessions, without it it passes clean_sessions().
template <class Run>
void expect_caught_and_clean(const std::string& property, const std::string& bug, Run run) {
  const rc::detail::TestResult with_bug = run(true, kPlantedSessions);
  EXPECT_TRUE(with_bug.template is<rc::detail::FailureResult>())
      << property << " did not catch the planted bug " << bug << ":\n"
      << result_message(with_bug);
  const rc::detail::TestResult without = run(false, clean_sessions());
  EXPECT_TRUE(without.template is<rc::detail::SuccessResult>())
      << property << " fails without any planted bug:\n"
      << result_message(without);
}

}  // namespace hil::client::logi::prop
