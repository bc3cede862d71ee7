// hil run as QA and CI use it: usage errors, the table and its exit status,
// the repro command, JUnit and the report folder, --repeat, --tags, --list.
// The scenarios are in tests/harness/data/run/.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "tests/apps/hil_cli_support.hpp"

namespace hil::test {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

const std::string kData = "tests/harness/data/run";

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
}

// The table's rows: the first two columns of the lines after the header,
// up to the first blank line.
std::vector<std::string> rows(const std::string& output) {
  std::vector<std::string> out;
  bool in_table = false;
  for (const auto& line : lines_of(output)) {
    if (line.rfind("SCENARIO", 0) == 0) {
      in_table = true;
      continue;
    }
    if (!in_table) continue;
    if (line.empty()) break;
    std::smatch m;
    if (std::regex_search(line, m, std::regex(R"(^(\S+(?: #\d+)?)\s+(\S+))")))
      out.push_back(m[1].str() + " " + m[2].str());
  }
  return out;
}

std::string last_line(const std::string& output) {
  const auto lines = lines_of(output);
  return lines.empty() ? std::string() : lines.back();
}

std::string read(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class TempDir {
 public:
  TempDir()
      : path_(std::filesystem::temp_directory_path() /
              ("hil_run_cli_test_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

TEST(HilRunCli, WithoutFilesIsAUsageError) {
  const auto r = run_hil("run");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("paths"));
}

TEST(HilRunCli, APathThatDoesNotExistIsAUsageError) {
  const auto r = run_hil("run " + kData + "/pass.yaml no-such-scenario.yaml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("no-such-scenario.yaml: no such file or folder"));
  EXPECT_THAT(r.output, Not(HasSubstr("passed")));
}

TEST(HilRunCli, AFolderWithoutScenariosIsAUsageError) {
  const auto r = run_hil("run scenarios/worlds");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("no scenario files"));
}

TEST(HilRunCli, MalformedOptionsAreUsageErrors) {
  EXPECT_EQ(run_hil("run " + kData + "/pass.yaml --set speed").exit_code, 2);
  EXPECT_EQ(run_hil("run " + kData + "/pass.yaml --repeat 0").exit_code, 2);
  EXPECT_EQ(run_hil("run " + kData + "/pass.yaml --jobs 0").exit_code, 2);
  EXPECT_EQ(run_hil("run " + kData + "/pass.yaml --seed x").exit_code, 2);
  EXPECT_EQ(run_hil("run " + kData + "/pass.yaml --tags nobody-has-this").exit_code, 2);
  const auto slack = run_hil("run " + kData + "/pass.yaml --slack 100");
  EXPECT_EQ(slack.exit_code, 2);
  EXPECT_THAT(slack.output, HasSubstr("'100' is not a duration (e.g. 100ms, 0.5s)"));
}

TEST(HilRunCli, SlackIsTakenAndCarriedIntoTheReproCommand) {
  EXPECT_EQ(run_hil("run " + kData + "/pass.yaml --slack 50ms").exit_code, 0);
  const auto r = run_hil("run " + kData + "/fail.yaml --seed 77 --slack 250ms");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("--seed 77 --slack 250ms\n"));
  EXPECT_THAT(r.output, HasSubstr("(± 0.250 s for real time)"));
}

TEST(HilRunCli, AFileThatDoesNotLoadIsAFailedRowWithItsLineAndColumn) {
  const auto r = run_hil("run " + kData + "/more/broken.yaml");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(rows(r.output), ElementsAre("broken FAIL"));
  EXPECT_THAT(r.output, HasSubstr("  error: " + kData + "/more/broken.yaml:6:5: "));
  EXPECT_THAT(r.output, HasSubstr("'pres FWD'"));
  EXPECT_THAT(r.output, HasSubstr("  repeat: hil run " + kData + "/more/broken.yaml\n"));
  EXPECT_EQ(last_line(r.output), "0 passed, 1 failed");
}

TEST(HilRunCli, APassingScenarioExitsZero) {
  const auto r = run_hil("run " + kData + "/pass.yaml");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(rows(r.output), ElementsAre("run-pass PASS"));
  EXPECT_THAT(r.output, HasSubstr(" s sim "));
  EXPECT_THAT(r.output, Not(HasSubstr("repeat:")));
  // Not a terminal: no colour codes in a CI log.
  EXPECT_THAT(r.output, Not(HasSubstr("\033[")));
  EXPECT_EQ(last_line(r.output), "1 passed, 0 failed");
}

TEST(HilRunCli, AFailingScenarioShowsEvidenceAndTheCommandThatRepeatsIt) {
  const auto r = run_hil("run " + kData + "/fail.yaml");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(rows(r.output), ElementsAre("run-fail FAIL"));
  EXPECT_THAT(r.output, HasSubstr("FAIL run-fail  (" + kData + "/fail.yaml, seed 9)\n"));
  EXPECT_THAT(r.output, HasSubstr("  expect line 11 (the car was told to run): "));
  EXPECT_THAT(r.output, HasSubstr("    evidence:\n"));
  EXPECT_THAT(r.output, HasSubstr("  repeat: hil run " + kData + "/fail.yaml --seed 9\n"));
  EXPECT_EQ(last_line(r.output), "0 passed, 1 failed");
}

TEST(HilRunCli, TheReproCommandCarriesTheSeedVariablesAndClient) {
  const auto r = run_hil("run " + kData + "/fail.yaml --seed 77 --set speed=30");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output,
              HasSubstr("  repeat: hil run " + kData + "/fail.yaml --seed 77 --set speed=30\n"));
  const auto exec = run_hil("run " + kData + "/fail.yaml --client-exec 'my-client {host} {port}'");
  EXPECT_EQ(exec.exit_code, 1);
  EXPECT_THAT(exec.output, HasSubstr("--seed 9 --client-exec 'my-client {host} {port}'\n"));
}

TEST(HilRunCli, AFolderRunsEveryScenarioInItSortedByFile) {
  // flaky.yaml has no seed of its own: seed 1 makes it fail.
  const auto r = run_hil("run " + kData + " -v --seed 1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(rows(r.output),
              ElementsAre("run-fail FAIL", "run-flaky FAIL", "broken FAIL", "run-pass PASS"));
  EXPECT_THAT(r.output, HasSubstr("skipped " + kData + "/more/not-a-scenario.yaml"));
  EXPECT_EQ(last_line(r.output), "1 passed, 3 failed");
}

TEST(HilRunCli, ParallelRunsKeepTheSameOrder) {
  const auto one = run_hil("run " + kData + " --seed 3 -j 1");
  const auto four = run_hil("run " + kData + " --seed 3 -j 4");
  EXPECT_EQ(rows(one.output), rows(four.output));
  EXPECT_EQ(rows(one.output).size(), 4U);
}

TEST(HilRunCli, WritesJunitAndTheReportFolder) {
  TempDir tmp;
  const auto junit = tmp.path() / "hil.xml";
  const auto report = tmp.path() / "report";
  const auto r = run_hil("run " + kData + "/pass.yaml " + kData + "/fail.yaml " + kData +
                         "/more/broken.yaml --junit '" + junit.string() + "' --report-dir '" +
                         report.string() + "'");
  EXPECT_EQ(r.exit_code, 1);

  const std::string xml = read(junit);
  EXPECT_THAT(xml, HasSubstr("<testsuite name=\"hil\" tests=\"3\" failures=\"2\""));
  EXPECT_THAT(xml, HasSubstr("classname=\"tests.harness.data.run\" name=\"run-pass\""));
  EXPECT_THAT(xml, HasSubstr("<failure message=\"expect line 11"));
  EXPECT_THAT(xml, HasSubstr("repeat: hil run " + kData + "/fail.yaml --seed 9"));
  if (std::system("python3 -c 'import xml.dom.minidom' >/dev/null 2>&1") == 0) {
    const std::string check =
        "python3 -c \"import sys, xml.dom.minidom as m; "
        "assert len(m.parse(sys.argv[1]).getElementsByTagName('testcase'))"
        " == 3\" '" +
        junit.string() + "'";
    EXPECT_EQ(std::system(check.c_str()), 0);
  }

  const std::string index = read(report / "index.html");
  EXPECT_THAT(index, HasSubstr("1 passed, 2 failed"));
  EXPECT_THAT(index, HasSubstr("href=\"run-pass/index.html\""));
  EXPECT_THAT(index, HasSubstr("href=\"run-fail/index.html\""));
  EXPECT_THAT(index, HasSubstr("href=\"broken/index.html\""));
  const std::string pass_page = read(report / "run-pass" / "index.html");
  EXPECT_THAT(pass_page, HasSubstr("<span class=\"pass\">PASS</span>"));
  EXPECT_THAT(pass_page, HasSubstr("release"));
  EXPECT_THAT(read(report / "run-fail" / "index.html"),
              HasSubstr("hil run " + kData + "/fail.yaml --seed 9"));
  const std::string ndjson = read(report / "run-pass" / "timeline.ndjson");
  EXPECT_THAT(ndjson, StartsWith("{\"t_ms\":"));
  EXPECT_THAT(ndjson, HasSubstr("MV:STOP"));
  EXPECT_THAT(read(report / "run-pass" / "trajectory.svg"), HasSubstr("<svg"));
  // The wire log: every frame each way, as the mock car's --log writes it.
  const std::string wire = read(report / "run-pass" / "wire.ndjson");
  EXPECT_THAT(wire, HasSubstr("\"link\":\"car0/link1\""));
  EXPECT_THAT(wire, HasSubstr("MV:STOP"));
  EXPECT_THAT(pass_page, HasSubstr("href=\"wire.ndjson\""));
  EXPECT_THAT(r.output, HasSubstr("report: " + (report / "index.html").string()));
}

TEST(HilRunCli, AnUnwritableJunitFileFailsTheRun) {
  const auto r = run_hil("run " + kData + "/pass.yaml --junit /nonexistent-dir/hil.xml");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("cannot write /nonexistent-dir/hil.xml"));
}

TEST(HilRunCli, RepeatRunsWithConsecutiveSeedsAndReportsFlakiness) {
  const auto r = run_hil("run " + kData + "/flaky.yaml --seed 1 --repeat 4");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(rows(r.output), ElementsAre("run-flaky #1 FLAKY", "run-flaky #2 PASS",
                                          "run-flaky #3 FLAKY", "run-flaky #4 PASS"));
  EXPECT_THAT(r.output, HasSubstr("repeat: hil run " + kData + "/flaky.yaml --seed 1\n"));
  EXPECT_THAT(r.output, HasSubstr("repeat: hil run " + kData + "/flaky.yaml --seed 3\n"));
  EXPECT_THAT(r.output,
              HasSubstr("FLAKY run-flaky (" + kData + "/flaky.yaml): 2 of 4 runs failed\n"));
  EXPECT_EQ(last_line(r.output), "0 passed, 1 failed");

  const auto steady = run_hil("run " + kData + "/pass.yaml --repeat 3");
  EXPECT_EQ(steady.exit_code, 0);
  EXPECT_THAT(rows(steady.output),
              ElementsAre("run-pass #1 PASS", "run-pass #2 PASS", "run-pass #3 PASS"));
  EXPECT_EQ(last_line(steady.output), "1 passed, 0 failed");
}

TEST(HilRunCli, TagsChooseWhichScenariosRun) {
  const std::string files = kData + "/pass.yaml " + kData + "/fail.yaml ";
  const auto smoke = run_hil("run " + files + "--tags smoke,nightly");
  EXPECT_EQ(smoke.exit_code, 0);
  EXPECT_THAT(rows(smoke.output), ElementsAre("run-pass PASS"));

  const auto excluded = run_hil("run " + files + "--exclude-tags fails-on-purpose");
  EXPECT_EQ(excluded.exit_code, 0);
  EXPECT_THAT(rows(excluded.output), ElementsAre("run-pass PASS"));

  // A file that does not load cannot say its tags; it stays in, so a
  // broken file never lets a gate pass.
  const auto broken = run_hil("run " + files + kData + "/more/broken.yaml --tags smoke");
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_THAT(rows(broken.output), ElementsAre("broken FAIL", "run-pass PASS"));
}

TEST(HilRunCli, OptionsBeforeTheFilesTakeOneValueEach) {
  const auto r = run_hil("run --tags smoke --set speed=30 --exclude-tags x " + kData +
                         "/pass.yaml " + kData + "/fail.yaml");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(rows(r.output), ElementsAre("run-pass PASS"));
}

TEST(HilRunCli, ListPrintsWhatWouldRunWithoutRunningIt) {
  const auto r = run_hil("run " + kData + "/pass.yaml " + kData + "/fail.yaml --list");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.output, kData + "/fail.yaml  run-fail  [logi, fails-on-purpose]\n" + kData +
                          "/pass.yaml  run-pass  [logi, smoke]\n");

  const auto broken = run_hil("run " + kData + "/more/broken.yaml --list");
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_THAT(broken.output, HasSubstr("does not load: " + kData + "/more/broken.yaml:6:5:"));
}

}  // namespace
}  // namespace hil::test
