// hil report merge's core: shards' JUnit documents and results.json joined
// into one, failed runs, missing and doubled scenarios named with the
// inputs they came from, and inputs that are not what they claim refused.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <pugixml.hpp>

#include "harness/report_merge.hpp"

namespace hil::harness {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

ReportEntry entry(const std::string& file, const std::string& name, bool pass = true) {
  ReportEntry e;
  e.outcome.file = file;
  e.outcome.name = name;
  e.outcome.seed = 9;
  e.outcome.wall_seconds = 0.25;
  e.outcome.repro_command = "hil run " + file + " --seed 9";
  if (!pass) e.outcome.error = "the car never answered";
  return e;
}

// A shard's JUnit file as hil run writes it.
MergeInput junit(const std::string& source, const std::vector<ReportEntry>& entries) {
  return {source, MergeInput::Kind::junit, junit_xml(entries)};
}

// A shard's report folder's results.json as hil run writes it.
MergeInput results(const std::string& source, std::vector<ReportEntry> entries) {
  report_folders(entries);
  std::vector<RunResult> runs;
  for (const auto& e : entries)
    runs.push_back(run_result(e));
  return {source, MergeInput::Kind::results, results_json(runs)};
}

// The merged document's <testcase> files, and its suite's counts.
struct Parsed {
  std::vector<std::string> files;
  int tests = 0;
  int failures = 0;
};
Parsed parse(const std::string& xml) {
  pugi::xml_document doc;
  EXPECT_TRUE(doc.load_string(xml.c_str()));
  Parsed p;
  const auto suite = doc.child("testsuite");
  EXPECT_STREQ(suite.attribute("name").as_string(), "hil");
  p.tests = suite.attribute("tests").as_int();
  p.failures = suite.attribute("failures").as_int();
  for (const auto& tc : suite.children("testcase"))
    p.files.emplace_back(tc.attribute("file").as_string());
  return p;
}

TEST(ReportMerge, JoinsJUnitShardsIntoOneSuite) {
  const auto merged =
      merge_reports({junit("s1.xml", {entry("sc/a.yaml", "a"), entry("sc/b.yaml", "b")}),
                     junit("s2.xml", {entry("sc/c.yaml", "c")})},
                    {std::vector<std::string>{"sc/a.yaml", "sc/b.yaml", "./sc/c.yaml"}});
  EXPECT_TRUE(merged.ok());
  const auto p = parse(merged.junit);
  EXPECT_THAT(p.files, ElementsAre("sc/a.yaml", "sc/b.yaml", "sc/c.yaml"));
  EXPECT_EQ(p.tests, 3);
  EXPECT_EQ(p.failures, 0);
  EXPECT_EQ(merged.summary(), "3 passed, 0 failed");
  EXPECT_TRUE(merged.problems().empty());
  // The test cases keep what hil run wrote in them.
  EXPECT_THAT(merged.junit, HasSubstr("repeat: hil run sc/a.yaml --seed 9"));
}

TEST(ReportMerge, AFailedRunFailsTheMergeAndNamesItsShard) {
  const auto merged = merge_reports({junit("s1.xml", {entry("sc/a.yaml", "a")}),
                                     junit("s2.xml", {entry("sc/b.yaml", "b", false)})});
  EXPECT_FALSE(merged.ok());
  EXPECT_EQ(parse(merged.junit).failures, 1);
  EXPECT_EQ(merged.summary(), "1 passed, 1 failed");
  EXPECT_THAT(merged.problems(), ElementsAre("failed: b (sc/b.yaml) in s2.xml"));
}

TEST(ReportMerge, NamesEachMissingScenario) {
  const auto merged =
      merge_reports({junit("s1.xml", {entry("sc/a.yaml", "a")})},
                    {std::vector<std::string>{"sc/a.yaml", "sc/b.yaml", "sc/sub/../c.yaml"}});
  EXPECT_FALSE(merged.ok());
  EXPECT_THAT(merged.missing, ElementsAre("sc/b.yaml", "sc/c.yaml"));
  EXPECT_THAT(merged.problems(), ElementsAre("missing: sc/b.yaml is in no input: no shard ran it",
                                             "missing: sc/c.yaml is in no input: no shard ran it"));
  EXPECT_EQ(merged.summary(), "1 passed, 0 failed, 2 missing");
}

TEST(ReportMerge, AnExpectedFileMatchesARunNamedFromAnotherFolder) {
  const auto merged = merge_reports(
      {junit("s1.xml", {entry("scenarios/logi/a.yaml", "a")}),
       junit("s2.xml", {entry("/builds/x/scenarios/logi/b.yaml", "b")})},
      {std::vector<std::string>{"/home/ci/scenarios/logi/a.yaml", "scenarios/logi/b.yaml",
                                "scenarios/logi/c.yaml", "other-logi/a.yaml"}});
  // Whole folder names only: "other-logi/a.yaml" is not "logi/a.yaml".
  EXPECT_THAT(merged.missing, ElementsAre("other-logi/a.yaml", "scenarios/logi/c.yaml"));
}

TEST(ReportMerge, NamesADoubledScenarioWithBothInputs) {
  const auto merged = merge_reports({junit("s1.xml", {entry("sc/a.yaml", "a")}),
                                     junit("s2.xml", {entry("sc/b.yaml", "b")}),
                                     junit("s3.xml", {entry("./sc/a.yaml", "a")})});
  EXPECT_FALSE(merged.ok());
  EXPECT_THAT(merged.problems(),
              ElementsAre("doubled: a (sc/a.yaml) ran in 2 inputs: s1.xml, s3.xml"));
  EXPECT_EQ(merged.summary(), "2 passed, 0 failed, 1 doubled");
}

TEST(ReportMerge, RepeatsOfOneScenarioInOneShardAreNotDoubled) {
  auto first = entry("sc/a.yaml", "a");
  first.repeats = 3;
  auto second = first;
  second.repeat = 1;
  auto third = first;
  third.repeat = 2;
  const auto merged = merge_reports({junit("s1.xml", {first, second, third})},
                                    {std::vector<std::string>{"sc/a.yaml"}});
  EXPECT_TRUE(merged.ok()) << ::testing::PrintToString(merged.problems());
  EXPECT_EQ(parse(merged.junit).tests, 3);
}

TEST(ReportMerge, JoinsReportFoldersRenamingClashingRunFolders) {
  // Two shards each have a scenario named "stop": both ran in folder "stop".
  const auto merged = merge_reports(
      {results("out-1", {entry("sc/logi/stop.yaml", "stop"), entry("sc/a.yaml", "a", false)}),
       results("out-2", {entry("sc/wr8/stop.yaml", "stop")})});
  ASSERT_EQ(merged.runs.size(), 3U);
  EXPECT_EQ(merged.runs[0].folder, "stop");
  EXPECT_EQ(merged.runs[1].folder, "a");
  EXPECT_EQ(merged.runs[2].folder, "stop-2");
  ASSERT_EQ(merged.copies.size(), 3U);
  EXPECT_EQ(merged.copies[2].input, 1U);
  EXPECT_EQ(merged.copies[2].from, "stop");
  EXPECT_EQ(merged.copies[2].to, "stop-2");
  EXPECT_THAT(merged.run_inputs, ElementsAre(0U, 0U, 1U));
  // The JUnit document is made from the results: the failure's text too.
  const auto p = parse(merged.junit);
  EXPECT_THAT(p.files, ElementsAre("sc/logi/stop.yaml", "sc/a.yaml", "sc/wr8/stop.yaml"));
  EXPECT_EQ(p.failures, 1);
  EXPECT_THAT(merged.junit, HasSubstr("the car never answered"));
  EXPECT_THAT(merged.problems(), ElementsAre("failed: a (sc/a.yaml) in out-1"));
  // The index links every run's renamed folder.
  const auto index = index_html(merged.runs, merged.summary());
  EXPECT_THAT(index, HasSubstr("href=\"stop-2/index.html\""));
  EXPECT_THAT(index, HasSubstr("<h1>2 passed, 1 failed</h1>"));
}

TEST(ReportMerge, ResultsJsonRoundTrips) {
  auto failed = entry("sc/a.yaml", "a", false);
  failed.outcome.tags = {"logi", "smoke"};
  auto skipped = entry("sc/b.yaml", "b");
  skipped.outcome.skipped = "needs the reference client";
  std::vector<ReportEntry> entries{failed, skipped, entry("sc/c.yaml", "c")};
  report_folders(entries);
  std::vector<RunResult> runs;
  for (const auto& e : entries)
    runs.push_back(run_result(e));
  EXPECT_EQ(runs[0].verdict, Verdict::fail);
  EXPECT_EQ(runs[0].first_failure, "the car never answered");
  EXPECT_THAT(runs[0].failure_text, HasSubstr("the car never answered"));
  EXPECT_EQ(runs[1].verdict, Verdict::skip);
  EXPECT_EQ(runs[1].first_failure, "needs the reference client");
  EXPECT_EQ(runs[2].verdict, Verdict::pass);
  EXPECT_EQ(parse_results_json(results_json(runs)), runs);
}

TEST(ReportMerge, RefusesInputsThatAreNotResults) {
  const auto error_of = [](const MergeInput& input) -> std::string {
    try {
      merge_reports({junit("ok.xml", {entry("sc/a.yaml", "a")}), input});
    } catch (const MergeInputError& e) {
      EXPECT_EQ(e.input(), 1U);
      return e.what();
    }
    return "no error";
  };
  EXPECT_THAT(error_of({"bad.xml", MergeInput::Kind::junit, "<testsuite><testcase"}),
              HasSubstr("bad.xml: not XML: "));
  EXPECT_EQ(error_of({"other.xml", MergeInput::Kind::junit, "<report/>"}),
            "other.xml: not JUnit XML (no <testsuite>)");
  EXPECT_EQ(error_of({"foreign.xml", MergeInput::Kind::junit,
                      "<testsuite><testcase name=\"t\"/></testsuite>"}),
            "foreign.xml: test case 't' has no file attribute (not written by hil run)");
  EXPECT_THAT(error_of({"out/results.json", MergeInput::Kind::results, "{"}),
              HasSubstr("out/results.json: not JSON: "));
  EXPECT_EQ(error_of({"out/results.json", MergeInput::Kind::results, "{\"runs\": []}"}),
            "out/results.json: not hil's run results (no \"format\": \"hil-results\")");
  EXPECT_EQ(error_of({"out/results.json", MergeInput::Kind::results,
                      R"({"format": "hil-results", "version": 1, "runs": [{"file": "a.yaml"}]})"}),
            "out/results.json: run 1 (a.yaml) has no verdict pass, fail or skip");
}

TEST(ReportMerge, AJUnitWrapperOfSuitesIsRead) {
  const std::string xml =
      "<testsuites><testsuite name=\"hil\"><testcase name=\"a\" file=\"sc/a.yaml\" "
      "time=\"1.5\"><skipped message=\"not here\"/></testcase></testsuite></testsuites>";
  const auto merged = merge_reports({{"wrapped.xml", MergeInput::Kind::junit, xml}});
  ASSERT_EQ(merged.runs.size(), 1U);
  EXPECT_EQ(merged.runs[0].verdict, Verdict::skip);
  EXPECT_EQ(merged.summary(), "0 passed, 0 failed, 1 skipped");
  EXPECT_TRUE(merged.ok());
}

}  // namespace
}  // namespace hil::harness
