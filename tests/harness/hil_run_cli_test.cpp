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
#include "tests/harness/junit_check.hpp"
#include "tests/harness/scratch_dir.hpp"
#include "tests/support/text.hpp"

namespace hil::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

const std::string kData = "tests/harness/data/run";

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

/// `hil run ARGS`: checks its exit code, the rows of its table and, when
/// given, its summary line; its output, for more checks.
std::string expect_table(const std::string& args, int exit_code,
                         const std::vector<std::string>& table, const std::string& summary = {}) {
  const auto r = run_hil("run " + args);
  EXPECT_EQ(r.exit_code, exit_code) << r.output;
  EXPECT_EQ(rows(r.output), table);
  if (!summary.empty()) EXPECT_EQ(last_line(r.output), summary);
  return r.output;
}

TEST(HilRunCli, WithoutFilesIsAUsageError) {
  expect_run(says("run", 2, {"paths"}));
}

TEST(HilRunCli, APathThatDoesNotExistIsAUsageError) {
  expect_run({.args = "run " + kData + "/pass.yaml no-such-scenario.yaml",
              .exit_code = 2,
              .contains = {"no-such-scenario.yaml: no such file or folder"},
              .lacks = {"passed"}});
}

TEST(HilRunCli, AFolderWithoutScenariosIsAUsageError) {
  expect_run(says("run scenarios/worlds", 2, {"no scenario files"}));
}

TEST(HilRunCli, MalformedOptionsAreUsageErrors) {
  for (const char* option :
       {"--set speed", "--repeat 0", "--jobs 0", "--seed x", "--tags nobody-has-this"})
    expect_run(says("run " + kData + "/pass.yaml " + option, 2, {}));
  expect_run(says("run " + kData + "/pass.yaml --slack 100", 2,
                  {"'100' is not a duration (e.g. 100ms, 0.5s)"}));
}

TEST(HilRunCli, SlackIsTakenAndCarriedIntoTheReproCommand) {
  EXPECT_EQ(run_hil("run " + kData + "/pass.yaml --slack 50ms").exit_code, 0);
  const auto r = run_hil("run " + kData + "/fail.yaml --seed 77 --slack 250ms");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("--seed 77 --slack 250ms\n"));
  EXPECT_THAT(r.output, HasSubstr("(± 0.250 s for real time)"));
}

TEST(HilRunCli, AFileThatDoesNotLoadIsAFailedRowWithItsLineAndColumn) {
  const auto out =
      expect_table(kData + "/more/broken.yaml", 1, {"broken FAIL"}, "0 passed, 1 failed");
  expect_contains(out, {"  error: " + kData + "/more/broken.yaml:6:5: ", "'pres FWD'",
                        "  repeat: hil run " + kData + "/more/broken.yaml\n"});
}

TEST(HilRunCli, APassingScenarioExitsZero) {
  const auto out = expect_table(kData + "/pass.yaml", 0, {"run-pass PASS"}, "1 passed, 0 failed");
  EXPECT_THAT(out, HasSubstr(" s sim "));
  EXPECT_THAT(out, Not(HasSubstr("repeat:")));
  // Not a terminal: no colour codes in a CI log.
  EXPECT_THAT(out, Not(HasSubstr("\033[")));
}

TEST(HilRunCli, AFailingScenarioShowsEvidenceAndTheCommandThatRepeatsIt) {
  const auto out = expect_table(kData + "/fail.yaml", 1, {"run-fail FAIL"}, "0 passed, 1 failed");
  expect_contains(out, {"FAIL run-fail  (" + kData + "/fail.yaml, seed 9)\n",
                        "  expect line 11 (the car was told to run): ", "    evidence:\n",
                        "  repeat: hil run " + kData + "/fail.yaml --seed 9\n"});
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

TEST(HilRunCli, AScenarioThatSetsTheReferenceClientIsSkippedForAnExternalProgram) {
  // `false` would fail any run it took part in: the skipped scenario never
  // starts it, and the other one (no settings) does.
  const auto out = expect_table(
      "scenarios/logi/logi-manual-keepalive.yaml " + kData + "/pass.yaml -v --client-exec false", 1,
      {"logi-manual-keepalive SKIP", "run-pass FAIL"}, "0 passed, 1 failed, 1 skipped");
  expect_contains(out, {"] SKIP logi-manual-keepalive",
                        "\nSKIP logi-manual-keepalive "
                        "(scenarios/logi/logi-manual-keepalive.yaml): it sets hil's reference "
                        "client's keepalive, keepalive_period (client: reference: settings:)"});
  expect_table("scenarios/logi/logi-manual-keepalive.yaml --client-exec false", 0,
               {"logi-manual-keepalive SKIP"}, "0 passed, 0 failed, 1 skipped");
}

TEST(HilRunCli, AFolderRunsEveryScenarioInItSortedByFile) {
  // flaky.yaml has no seed of its own: seed 1 makes it fail.
  const auto out = expect_table(kData + " -v --seed 1", 1,
                                {"run-fail FAIL", "run-flaky FAIL", "broken FAIL", "run-pass PASS"},
                                "1 passed, 3 failed");
  EXPECT_THAT(out, HasSubstr("skipped " + kData + "/more/not-a-scenario.yaml"));
}

TEST(HilRunCli, ParallelRunsKeepTheSameOrder) {
  const auto one = run_hil("run " + kData + " --seed 3 -j 1");
  const auto four = run_hil("run " + kData + " --seed 3 -j 4");
  EXPECT_EQ(rows(one.output), rows(four.output));
  EXPECT_EQ(rows(one.output).size(), 4U);
}

TEST(HilRunCli, WritesJunitAndTheReportFolder) {
  const ScratchDir tmp("hil-run-cli");
  const auto junit = tmp.path() / "hil.xml";
  const auto report = tmp.path() / "report";
  const auto r = run_hil("run " + kData + "/pass.yaml " + kData + "/fail.yaml " + kData +
                         "/more/broken.yaml --junit '" + junit.string() + "' --report-dir '" +
                         report.string() + "'");
  EXPECT_EQ(r.exit_code, 1);

  const std::string xml = read_file(junit);
  EXPECT_THAT(xml, HasSubstr("<testsuite name=\"hil\" tests=\"3\" failures=\"2\""));
  EXPECT_THAT(xml, HasSubstr("classname=\"tests.harness.data.run\" name=\"run-pass\""));
  EXPECT_THAT(xml, HasSubstr("<failure message=\"expect line 11"));
  EXPECT_THAT(xml, HasSubstr("repeat: hil run " + kData + "/fail.yaml --seed 9"));
  if (python_xml_available()) EXPECT_EQ(python_checks_junit(junit, 3), 0);

  const std::string index = read_file(report / "index.html");
  EXPECT_THAT(index, HasSubstr("1 passed, 2 failed"));
  EXPECT_THAT(index, HasSubstr("href=\"run-pass/index.html\""));
  EXPECT_THAT(index, HasSubstr("href=\"run-fail/index.html\""));
  EXPECT_THAT(index, HasSubstr("href=\"broken/index.html\""));
  const std::string pass_page = read_file(report / "run-pass" / "index.html");
  EXPECT_THAT(pass_page, HasSubstr("<span class=\"pass\">PASS</span>"));
  EXPECT_THAT(pass_page, HasSubstr("release"));
  EXPECT_THAT(read_file(report / "run-fail" / "index.html"),
              HasSubstr("hil run " + kData + "/fail.yaml --seed 9"));
  const std::string ndjson = read_file(report / "run-pass" / "timeline.ndjson");
  EXPECT_THAT(ndjson, StartsWith("{\"t_ms\":"));
  EXPECT_THAT(ndjson, HasSubstr("MV:STOP"));
  EXPECT_THAT(read_file(report / "run-pass" / "trajectory.svg"), HasSubstr("<svg"));
  // The wire log: every frame each way, as the mock car's --log writes it.
  const std::string wire = read_file(report / "run-pass" / "wire.ndjson");
  EXPECT_THAT(wire, HasSubstr("\"link\":\"car0/link1\""));
  EXPECT_THAT(wire, HasSubstr("MV:STOP"));
  EXPECT_THAT(pass_page, HasSubstr("href=\"wire.ndjson\""));
  EXPECT_THAT(r.output, HasSubstr("report: " + (report / "index.html").string()));
}

TEST(HilRunCli, AnUnwritableJunitFileFailsTheRun) {
  expect_run(says("run " + kData + "/pass.yaml --junit /nonexistent-dir/hil.xml", 1,
                  {"cannot write /nonexistent-dir/hil.xml"}));
}

TEST(HilRunCli, RepeatRunsWithConsecutiveSeedsAndReportsFlakiness) {
  const auto out = expect_table(
      kData + "/flaky.yaml --seed 1 --repeat 4", 1,
      {"run-flaky #1 FLAKY", "run-flaky #2 PASS", "run-flaky #3 FLAKY", "run-flaky #4 PASS"},
      "0 passed, 1 failed");
  expect_contains(out, {"repeat: hil run " + kData + "/flaky.yaml --seed 1\n",
                        "repeat: hil run " + kData + "/flaky.yaml --seed 3\n",
                        "FLAKY run-flaky (" + kData + "/flaky.yaml): 2 of 4 runs failed\n"});

  expect_table(kData + "/pass.yaml --repeat 3", 0,
               {"run-pass #1 PASS", "run-pass #2 PASS", "run-pass #3 PASS"}, "1 passed, 0 failed");
}

TEST(HilRunCli, TagsChooseWhichScenariosRun) {
  const std::string files = kData + "/pass.yaml " + kData + "/fail.yaml ";
  expect_table(files + "--tags smoke,nightly", 0, {"run-pass PASS"});
  expect_table(files + "--exclude-tags fails-on-purpose", 0, {"run-pass PASS"});
  // A file that does not load cannot say its tags; it stays in, so a
  // broken file never lets a gate pass.
  expect_table(files + kData + "/more/broken.yaml --tags smoke", 1,
               {"broken FAIL", "run-pass PASS"});
}

TEST(HilRunCli, OptionsBeforeTheFilesTakeOneValueEach) {
  expect_table("--tags smoke --set speed=30 --exclude-tags x " + kData + "/pass.yaml " + kData +
                   "/fail.yaml",
               0, {"run-pass PASS"});
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

// The LOGI scenarios tagged `replay` need nothing the LOGI probe does not
// record (answers, silences, the STAT period; no motion, no exact STAT
// grid, no mode the car keeps), and pass against a recorded car: a probe
// of hil's own mock, scenarios/captures/logi-probe.ndjson.
TEST(HilRunCli, TheReplayTaggedLogiScenariosPassAgainstARecordedCar) {
  expect_run(says("run scenarios/logi --tags replay --replay scenarios/captures/logi-probe.ndjson",
                  0, {"16 passed, 0 failed"}));
}

TEST(HilRunCli, ReplaySkipsScenariosOfAnotherCarAndRefusesABadCapture) {
  expect_run(
      says("run scenarios/arduino/arduino-commands.yaml --replay "
           "scenarios/captures/logi-probe.ndjson",
           0,
           {"its car is arduino and --replay scenarios/captures/logi-probe.ndjson is a "
            "capture of logi",
            "0 passed, 0 failed, 1 skipped"}));
  expect_run(
      says("run scenarios/logi/logi-buttons.yaml --replay "
           "scenarios/captures/logi-session.txt",
           2, {"hil run: --replay: ", "logi-session.txt:1:"}));
  expect_run(says("run scenarios/logi/logi-buttons.yaml --unmatched silent", 2,
                  {"--unmatched needs --replay"}));
}

}  // namespace
}  // namespace hil::test
