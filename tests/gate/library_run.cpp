#include "tests/gate/library_run.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <exception>
#include <utility>
#include <variant>

#include "config/error.hpp"
#include "harness/runner.hpp"
#include "harness/scenario_yaml.hpp"

namespace hil::harness::gate {
namespace {

namespace fs = std::filesystem;

// A client that piles up records at one instant of virtual time is
// stopped (as the run stops a client at its end: no reconnect), with a
// notice in the timeline. A client that reconnects with no delay to a car
// that refuses or drops it at once never lets the virtual clock move, and
// each attempt adds to the timeline; no correct run has this many records
// at one instant.
constexpr std::size_t kRecordsAtOneInstant = 10'000;

class StopsWhenSpinning final : public ForwardingClient {
 public:
  StopsWhenSpinning(std::unique_ptr<ScenarioClient> client, RunTimeline& timeline,
                    link::Executor& executor)
      : ForwardingClient(std::move(client)), timeline_(timeline) {
    listener_ = timeline_.listen([this, &executor](const Record& r) {
      if (r.at != instant_) {
        instant_ = r.at;
        at_instant_ = 0;
      }
      if (++at_instant_ != kRecordsAtOneInstant) return;
      // Records are not added from a listener: the stop comes next turn.
      executor.post([this, alive = alive_] {
        if (!*alive) return;
        timeline_.add(ClientKind::notice,
                      {{"text", "the client was stopped: " + std::to_string(kRecordsAtOneInstant) +
                                    " records at one instant"}});
        inner().stop();
      });
    });
  }
  ~StopsWhenSpinning() override {
    *alive_ = false;
    timeline_.unlisten(listener_);
  }

 private:
  RunTimeline& timeline_;
  RunTimeline::ListenerId listener_ = 0;
  Time instant_{-1};
  std::size_t at_instant_ = 0;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

// The library's scenario files, in name order.
std::vector<fs::path> library_files(const fs::path& library) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(library))
    if (entry.is_regular_file() && entry.path().extension() == ".yaml")
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

std::string LibraryRun::failures_text() const {
  std::string text;
  for (const auto& [name, why] : failed)
    text += "\n  " + name + ": " + why;
  return text.empty() ? "\n  (none)" : text;
}

LibraryRun run_library(const fs::path& library, const ClientFactory& make) {
  LibraryRun run;
  RunOptions options;
  options.reference_client = [&make, &run](const ClientSetup& setup) {
    std::unique_ptr<ScenarioClient> client = make(setup);
    if (!client) return client;
    ++run.replaced;
    return std::unique_ptr<ScenarioClient>(std::make_unique<StopsWhenSpinning>(
        std::move(client), setup.timeline, setup.context.executor));
  };
  for (const auto& file : library_files(library)) {
    Scenario scenario;
    try {
      scenario = load_scenario(file.string());
    } catch (const config::ConfigError& e) {
      run.load_problems.push_back(e.what());
      continue;
    } catch (const std::exception& e) {
      run.load_problems.push_back(file.string() + ": " + e.what());
      continue;
    }
    const auto* reference = std::get_if<ReferenceClient>(&scenario.client);
    if (reference == nullptr || reference->real_time) continue;
    options.seed = scenario.seed.value_or(kLibrarySeed);
    const ScenarioOutcome outcome = run_scenario(scenario, options);
    ++run.ran;
    run.names.insert(outcome.name);
    if (!outcome.passed()) run.failed[outcome.name] = outcome.first_failure();
  }
  return run;
}

void expect_whole_library_ran(const fs::path& library, const LibraryRun& run) {
  for (const auto& problem : run.load_problems)
    ADD_FAILURE() << "a library file does not load: " << problem;
  EXPECT_GT(run.ran, 0u) << "no scenario in " << library;
  EXPECT_EQ(run.replaced, run.ran) << "some scenarios did not run on the planted-bug client";
}

void expect_caught_by(const fs::path& library, const LibraryRun& run, const std::string& bug,
                      const std::vector<std::string>& catchers) {
  EXPECT_FALSE(run.failed.empty()) << "the whole library passes with the planted bug " << bug;
  if (catchers.empty())
    ADD_FAILURE() << "no scenario is named to catch the planted bug " << bug
                  << "; the library failed in:" << run.failures_text();
  for (const auto& scenario : catchers) {
    if (!run.names.count(scenario)) {
      ADD_FAILURE() << scenario << ", named to catch " << bug << ", is not in " << library
                    << " (or asks for real time)";
      continue;
    }
    EXPECT_TRUE(run.failed.count(scenario)) << scenario << " passes with the planted bug " << bug
                                            << "; the library failed in:" << run.failures_text();
  }
}

}  // namespace hil::harness::gate
