// hil run -j: how many runs go at once and in which order they start.
// Runs in real time mostly wait, so `-j auto` (the default) runs many of
// them at once where it runs one virtual-time run per core; and the
// longest runs start first, so a batch does not end waiting on one long
// run started last.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>

#include "tests/apps/hil_cli_support.hpp"
#include "tests/harness/scratch_dir.hpp"
#include "tests/support/text.hpp"

namespace hil::test {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// A LOGI scenario whose run waits `wait` on its clock, its reference
// client in real time when `real_time` (on a real socket), else in virtual
// time.
void write_waiting_scenario(const std::filesystem::path& file, const std::string& name,
                            const std::string& wait, bool real_time) {
  std::ofstream out(file);
  out << "name: " << name << "\ncar: logi\nseed: 1\ntimeout: 30s\nsettle: 100ms\n";
  if (real_time) out << "client: {reference: {real_time: true}}\n";
  out << "steps:\n  - connect\n  - wait: " << wait << "\n  - disconnect\n";
}

// The scenario names in the order -v reported them finished.
std::vector<std::string> finish_order(const std::string& output) {
  std::vector<std::string> names;
  const std::regex progress(R"(^\[\d+/\d+\] (?:PASS|FAIL|SKIP) (\S+))");
  for (const auto& line : lines_of(output)) {
    std::smatch m;
    if (std::regex_search(line, m, progress)) names.push_back(m[1].str());
  }
  return names;
}

TEST(HilRunJobs, WithOneAtATimeTheLongestRunStartsFirstWhateverTheFilesOrder) {
  const ScratchDir dir("hil-jobs-order");
  write_waiting_scenario(dir.path() / "a-short.yaml", "a-short", "1s", false);
  write_waiting_scenario(dir.path() / "b-medium.yaml", "b-medium", "5s", false);
  write_waiting_scenario(dir.path() / "c-long.yaml", "c-long", "20s", false);
  const auto r = run_hil("run " + dir.path().string() + " -j 1 -v");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(finish_order(r.output), ElementsAre("c-long", "b-medium", "a-short")) << r.output;
  // The table keeps the files' order.
  EXPECT_LT(r.output.find("\na-short "), r.output.find("\nc-long ")) << r.output;
}

// Eight runs of 3 s each in real time: two at a time (one per core on the
// 2-core CI machine, the default before runs in real time had their own
// width) take at least 12 s; -j auto runs them side by side.
TEST(HilRunJobs, AutoRunsRealTimeRunsSideBySide) {
  const ScratchDir dir("hil-jobs-auto");
  for (int i = 0; i < 8; ++i) {
    const std::string name = "wait-" + std::to_string(i);
    write_waiting_scenario(dir.path() / (name + ".yaml"), name, "3s", true);
  }
  const auto start = std::chrono::steady_clock::now();
  const auto r = run_hil("run " + dir.path().string() + " -j auto");
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("8 passed, 0 failed"));
  // Side by side: about 3.2 s; 9 s leaves a loaded machine room and is
  // still well under the 12 s of two at a time.
  EXPECT_LT(wall_s, 9.0) << r.output;
}

TEST(HilRunJobs, AnExplicitWidthHoldsForRunsInRealTimeToo) {
  const ScratchDir dir("hil-jobs-two");
  for (int i = 0; i < 4; ++i) {
    const std::string name = "wait-" + std::to_string(i);
    write_waiting_scenario(dir.path() / (name + ".yaml"), name, "1500ms", true);
  }
  const auto start = std::chrono::steady_clock::now();
  const auto r = run_hil("run " + dir.path().string() + " -j 2");
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Two rounds of two: at least 3 s, however fast the machine.
  EXPECT_GE(wall_s, 3.0) << r.output;
}

TEST(HilRunJobs, AWidthThatIsNotANumberOrAutoIsAUsageError) {
  for (const char* jobs : {"0", "many", "2x", "1025"}) {
    const auto r = run_hil(std::string("run tests/harness/data/run/pass.yaml -j ") + jobs);
    EXPECT_EQ(r.exit_code, 2) << jobs << '\n' << r.output;
    EXPECT_THAT(r.output, HasSubstr("--jobs: expected a number of runs from 1 to 1024, or auto"))
        << jobs;
  }
}

}  // namespace
}  // namespace hil::test
