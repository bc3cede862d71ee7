// A scenario library run whole in virtual time with the reference client
// made through RunOptions::reference_client, for tests that show the
// library rejects a client with a planted bug and passes it without:
// tests/gate/planted_bug_library_test.cpp, for every car with planted bugs.

#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "harness/client_under_test.hpp"
#include "harness/scenario_client.hpp"

namespace hil::harness::gate {

/// The seed of a scenario that names none (one with random faults), so each
/// run of a library is the same every time.
inline constexpr std::uint64_t kLibrarySeed = 20261204;

/// What a run of a whole library found.
struct LibraryRun {
  std::size_t ran = 0;                        ///< scenarios run
  std::size_t replaced = 0;                   ///< of those, run on the client the factory made
  std::set<std::string> names;                ///< of the scenarios run
  std::map<std::string, std::string> failed;  ///< name -> first failure
  std::vector<std::string> load_problems;     ///< files that did not load

  /// One line per failed scenario, or "(none)".
  std::string failures_text() const;
};

/// Makes the reference client of one scenario's run; nullptr keeps hil's own.
using ClientFactory = std::function<std::unique_ptr<ScenarioClient>(const ClientSetup&)>;

/// Runs every scenario of `library` (its *.yaml files, in name order) that
/// uses the reference client in virtual time, with the client `make`
/// returns. A scenario that asks for real time is left out: its verdict
/// would rest on the machine's timing. A client that piles up records at
/// one instant of virtual time (one that reconnects with no delay to a car
/// that turns it away never lets the clock move) is stopped, with a notice
/// in the timeline.
LibraryRun run_library(const std::filesystem::path& library, const ClientFactory& make);

/// What every run must show whatever the client: the library loaded and
/// ran, every scenario on the client the factory made (gtest failures).
void expect_whole_library_ran(const std::filesystem::path& library, const LibraryRun& run);

/// The scenarios named to catch `bug` each failed in `run`, and the run
/// failed at all (gtest failures naming the bug and what failed instead).
void expect_caught_by(const std::filesystem::path& library, const LibraryRun& run,
                      const std::string& bug, const std::vector<std::string>& catchers);

}  // namespace hil::harness::gate
