// What `hil run` shows people and CI for finished runs: the console table,
// failure blocks with evidence and the repro command, JUnit XML, and the
// report folder, from outcomes built by hand.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "harness/report.hpp"
#include "tests/harness/junit_check.hpp"
#include "tests/support/text.hpp"
#include "view/drawing.hpp"

namespace hil::harness {
namespace {

using hil::test::expect_contains;
using hil::test::lines_of;
using hil::test::read_file;
using std::chrono::milliseconds;
using ::testing::HasSubstr;
using ::testing::Not;

Record frame(int at_ms, const char* dir, const char* stage, const char* text, bool valid = true) {
  nlohmann::json data = {
      {"dir", dir}, {"stage", stage}, {"frame", "MV:STOP"}, {"text", text}, {"valid", valid}};
  if (!valid) data["error"] = "checksum";
  return Record{milliseconds(at_ms), WireKind::frame, data};
}

StepOutcome step(int line, const char* text, bool ok, const char* reason, int from_ms, int to_ms) {
  StepOutcome s;
  s.line = line;
  s.text = text;
  s.phase = "steps";
  s.ok = ok;
  s.reason = reason;
  s.started = milliseconds(from_ms);
  s.ended = milliseconds(to_ms);
  return s;
}

ReportEntry entry(ScenarioOutcome outcome, int repeat = 0, int repeats = 1) {
  ReportEntry e;
  e.outcome = std::move(outcome);
  e.repeat = repeat;
  e.repeats = repeats;
  return e;
}

/// A run of scenarios/logi/`stem`.yaml, named `name`, with `seed`, that
/// took `run_ms` of run time in `wall_seconds`; its repro command is
/// `hil run FILE --seed SEED`.
ScenarioOutcome logi_run(const std::string& stem, const std::string& name, std::uint64_t seed,
                         int run_ms, double wall_seconds) {
  ScenarioOutcome o;
  o.file = "scenarios/logi/" + stem + ".yaml";
  o.name = name;
  o.seed = seed;
  o.run_time = milliseconds(run_ms);
  o.wall_seconds = wall_seconds;
  o.repro_command = "hil run " + o.file + " --seed " + std::to_string(seed);
  return o;
}

ScenarioOutcome passing() {
  ScenarioOutcome o = logi_run("drive", "drive-forward", 7, 12345, 0.25);
  o.tags = {"logi", "smoke"};
  o.steps = {step(4, "connect", true, "", 0, 120), step(5, "speed 50", true, "", 120, 130)};
  o.expectations = {ExpectationOutcome{9, "car received SP:050", true, "", {}, {}, {}}};
  o.timeline.add(frame(125, "to_car", "delivered", "LOGI:SP:050:D7#"));
  return o;
}

ScenarioOutcome failed_step() {
  ScenarioOutcome o = logi_run("reject", "rejected-mode", 11, 2000, 0.1);
  o.timeline.add(milliseconds(1000), StepKind::start, {{"text", "mode MAN"}});
  o.timeline.add(frame(1000, "to_car", "delivered", "LOGI:MO:MAN:xx#"));
  o.timeline.add(milliseconds(1100), SimKind::sample, {{"x_m", 1.0}});
  o.timeline.add(milliseconds(1500), ClientKind::notice, {{"text", "mode refused"}});
  o.steps = {step(4, "connect", true, "", 0, 100),
             step(6, "mode MAN", false, "the car refused MO:MAN", 1000, 1500),
             step(7, "press FWD", false, "not run", 1500, 1500)};
  o.steps[2].ran = false;
  return o;
}

ScenarioOutcome failed_expectation() {
  ScenarioOutcome o = logi_run("release", "release-sends-stop", 42, 6000, 0.5);
  o.steps = {step(4, "press FWD", true, "", 0, 10)};
  ExpectationOutcome e;
  e.line = 31;
  e.label = "car received MV:STOP within 300 ms of the release";
  e.passed = false;
  e.message = "no 'car received MV:STOP' between 5.000 s and 5.300 s; the nearest at 5.812 s";
  e.window_from = milliseconds(5000);
  e.window_to = milliseconds(5300);
  e.evidence = {frame(5000, "to_car", "sent", "LOGI:MV:STOP:A1#"),
                frame(5812, "to_car", "delivered", "LOGI:MV:STOP:A1#")};
  o.expectations = {e};
  return o;
}

ScenarioOutcome load_error() {
  ScenarioOutcome o;
  o.file = "scenarios/logi/broken.yaml";
  o.name = "broken";
  o.error = "scenarios/logi/broken.yaml:12:9: step 3: unknown LOGI action 'pres FWD'";
  o.repro_command = "hil run scenarios/logi/broken.yaml";
  return o;
}

std::vector<ReportEntry> all_four() {
  return {entry(passing()), entry(failed_step()), entry(failed_expectation()), entry(load_error())};
}

std::string console(const std::vector<ReportEntry>& entries, ConsoleOptions options = {}) {
  std::ostringstream out;
  write_console(out, entries, options);
  return out.str();
}

TEST(ReportConsole, OneRowPerRunAndTheSummaryLineLast) {
  const std::string text = console(all_four());
  const auto lines = lines_of(text);
  ASSERT_GE(lines.size(), 6U);
  EXPECT_THAT(lines[0], HasSubstr("SCENARIO"));
  EXPECT_THAT(lines[1], HasSubstr("drive-forward"));
  EXPECT_THAT(lines[1], HasSubstr("PASS"));
  EXPECT_THAT(lines[1], HasSubstr("12.345 s sim"));
  EXPECT_THAT(lines[1], HasSubstr("0.250 s"));
  EXPECT_THAT(lines[2], HasSubstr("rejected-mode"));
  EXPECT_THAT(lines[2], HasSubstr("FAIL"));
  EXPECT_THAT(lines[2], HasSubstr("step line 6 (mode MAN): the car refused MO:MAN"));
  EXPECT_THAT(lines[3], HasSubstr("expect line 31: no 'car received MV:STOP'"));
  EXPECT_THAT(lines[4], HasSubstr("broken.yaml:12:9: step 3"));
  EXPECT_EQ(lines.back(), "1 passed, 3 failed");
}

TEST(ReportConsole, EveryFailureHasItsBlockWithEvidenceAndTheCommandThatRepeatsIt) {
  const std::string text = console(all_four());
  expect_contains(text, {"FAIL release-sends-stop  (scenarios/logi/release.yaml, seed 42)",
                         "    window: 5.000 s .. 5.300 s\n",
                         "        5.000 s  wire    client sent  LOGI:MV:STOP:A1#\n",
                         "        5.812 s  wire    car received  LOGI:MV:STOP:A1#\n",
                         "\n  repeat: hil run scenarios/logi/release.yaml --seed 42\n",
                         "\n  repeat: hil run scenarios/logi/reject.yaml --seed 11\n",
                         "\n  repeat: hil run scenarios/logi/broken.yaml\n"});
  EXPECT_THAT(text, Not(HasSubstr("repeat: hil run scenarios/logi/drive.yaml")));
}

TEST(ReportConsole, AFailedStepShowsWhatHappenedBeforeItButNotChassisSamples) {
  const std::string block = failure_text(failed_step());
  EXPECT_THAT(block, HasSubstr("step line 6 (mode MAN) failed at 1.500 s: the car refused"));
  EXPECT_THAT(block, HasSubstr("car received  LOGI:MO:MAN:xx#"));
  EXPECT_THAT(block, HasSubstr("client  notice: mode refused"));
  EXPECT_THAT(block, Not(HasSubstr("sample")));
  EXPECT_THAT(block, HasSubstr("1 later step(s) did not run"));
}

TEST(ReportConsole, ALoadErrorIsItsWholeFailure) {
  const std::string block = failure_text(load_error());
  EXPECT_EQ(block,
            "FAIL broken  (scenarios/logi/broken.yaml)\n"
            "  error: scenarios/logi/broken.yaml:12:9: step 3: unknown LOGI action 'pres FWD'\n"
            "  repeat: hil run scenarios/logi/broken.yaml\n");
}

TEST(ReportConsole, ColoursOnlyWhenAsked) {
  EXPECT_THAT(console(all_four()), Not(HasSubstr("\033[")));
  const std::string coloured = console(all_four(), ConsoleOptions{true, 100});
  EXPECT_THAT(coloured, HasSubstr("\033[32mPASS"));
  EXPECT_THAT(coloured, HasSubstr("\033[31mFAIL"));
  // The summary stays plain, so scripts can find it.
  EXPECT_EQ(lines_of(coloured).back(), "1 passed, 3 failed");
}

TEST(ReportConsole, NoColourForAPipeOrWithNoColorSet) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  EXPECT_FALSE(want_color(fds[1]));
  ::close(fds[0]);
  ::close(fds[1]);
}

TEST(ReportConsole, LongFailuresAreCutToTheWidth) {
  auto o = failed_expectation();
  o.expectations[0].message = std::string(300, 'x');
  const auto lines = lines_of(console({entry(o)}, ConsoleOptions{false, 80}));
  ASSERT_GE(lines.size(), 2U);
  EXPECT_LE(lines[1].size(), 80U);
  EXPECT_THAT(lines[1], HasSubstr("..."));
}

TEST(ReportConsole, AScenarioThatBothPassedAndFailedIsFlakyAndCountsAsFailed) {
  auto bad = failed_expectation();
  auto good = failed_expectation();
  good.expectations[0].passed = true;
  good.seed = 43;
  bad.seed = 44;
  std::vector<ReportEntry> entries{entry(failed_expectation(), 0, 3), entry(good, 1, 3),
                                   entry(bad, 2, 3), entry(passing())};
  const std::string text = console(entries);
  const auto lines = lines_of(text);
  EXPECT_THAT(lines[1], HasSubstr("release-sends-stop #1"));
  EXPECT_THAT(lines[1], HasSubstr("FLAKY"));
  EXPECT_THAT(lines[2], HasSubstr("release-sends-stop #2"));
  EXPECT_THAT(lines[2], HasSubstr("PASS"));
  EXPECT_THAT(text, HasSubstr("FLAKY release-sends-stop (scenarios/logi/release.yaml): 2 of 3 "
                              "runs failed\n"));
  EXPECT_THAT(text, HasSubstr("run 3 of 3:\nFAIL release-sends-stop"));
  EXPECT_EQ(lines.back(), "1 passed, 1 failed");

  const auto s = summarize(entries);
  ASSERT_EQ(s.size(), 2U);
  EXPECT_EQ(s[0].verdict, Verdict::flaky);
  EXPECT_EQ(s[0].runs, 3);
  EXPECT_EQ(s[1].verdict, Verdict::pass);
}

ScenarioOutcome skipped() {
  ScenarioOutcome o = logi_run("keepalive", "manual-keepalive", 1, 0, 0.0);
  o.skipped = "it sets hil's reference client's keepalive";
  return o;
}

TEST(ReportConsole, ASkippedScenarioReadsSkipWithItsReasonAndFailsNothing) {
  std::vector<ReportEntry> entries{entry(skipped(), 0, 2), entry(skipped(), 1, 2),
                                   entry(passing())};
  const std::string text = console(entries);
  const auto lines = lines_of(text);
  EXPECT_THAT(lines[1], HasSubstr("manual-keepalive #1"));
  EXPECT_THAT(lines[1], HasSubstr("SKIP"));
  EXPECT_THAT(lines[1], HasSubstr("it sets hil's reference client's keepalive"));
  EXPECT_THAT(lines[2], HasSubstr("SKIP"));
  EXPECT_THAT(text, HasSubstr("\nSKIP manual-keepalive (scenarios/logi/keepalive.yaml): it sets "
                              "hil's reference client's keepalive\n\n"))
      << "the reason once, not once per repeat";
  EXPECT_THAT(text, Not(HasSubstr("\nFAIL")));
  EXPECT_EQ(lines.back(), "1 passed, 0 failed, 1 skipped");

  const auto s = summarize(entries);
  ASSERT_EQ(s.size(), 2U);
  EXPECT_EQ(s[0].verdict, Verdict::skip);
  EXPECT_EQ(s[0].failed_runs, 0);
  EXPECT_EQ(summary_line({entry(passing())}), "1 passed, 0 failed") << "no skip, no mention";
}

TEST(ReportConsole, RecordsReadAsOneLineEach) {
  EXPECT_EQ(format_record(frame(5000, "to_car", "delivered", "LOGI:MV:STOP:A1#\r\n")),
            "    5.000 s  wire    car received  LOGI:MV:STOP:A1#\\r\\n");
  EXPECT_EQ(format_record(frame(12, "to_client", "sent", "LOGI:X:00#", false)),
            "    0.012 s  wire    car sent  LOGI:X:00#  (invalid: checksum)");
  EXPECT_EQ(
      format_record(Record{milliseconds(6000), ClientKind::connection, {{"state", "connected"}}}),
      "    6.000 s  client  connection connected");
  EXPECT_EQ(format_record(Record{milliseconds(90000), SimKind::station, {{"station", 2}}}),
            "   90.000 s  sim     station 2");
  // A kind with no words of its own shows everything it carries.
  EXPECT_EQ(format_record(Record{milliseconds(1), ClientKind::start, {{"a", 1}}}),
            "    0.001 s  client  start {\"a\":1}");
}

// Markup outside tags must be only what the writer put there: after
// removing every tag, no '<' may remain and every '&' starts an entity.
void expect_well_escaped(const std::string& xml) {
  std::string text;
  bool in_tag = false;
  char quote = 0;
  for (const char c : xml) {
    if (in_tag) {
      if (quote != 0) {
        ASSERT_NE(c, '<') << "raw '<' in an attribute";
        if (c == quote) quote = 0;
        if (c != quote) text += c;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '>') {
        in_tag = false;
      }
    } else if (c == '<') {
      in_tag = true;
    } else {
      text += c;
    }
  }
  for (std::size_t i = text.find('&'); i != std::string::npos; i = text.find('&', i + 1)) {
    const auto semi = text.find(';', i);
    ASSERT_NE(semi, std::string::npos);
    const std::string entity = text.substr(i, semi - i + 1);
    EXPECT_TRUE(entity == "&amp;" || entity == "&lt;" || entity == "&gt;" || entity == "&quot;" ||
                entity == "&#39;")
        << entity;
  }
}

TEST(ReportJunit, OneTestcasePerRunWithTheFailureAndItsEvidence) {
  const std::string xml = junit_xml(all_four());
  EXPECT_THAT(xml, HasSubstr("<testsuite name=\"hil\" tests=\"4\" failures=\"3\""));
  EXPECT_THAT(xml, HasSubstr("<testcase classname=\"scenarios.logi\" name=\"drive-forward\" "
                             "time=\"0.250\""));
  EXPECT_THAT(xml, HasSubstr("<failure message=\"expect line 31: no &#39;car received "
                             "MV:STOP&#39; between 5.000 s and 5.300 s; the nearest at 5.812 s\""));
  EXPECT_THAT(xml, HasSubstr("car received  LOGI:MV:STOP:A1#"));
  EXPECT_THAT(xml, HasSubstr("repeat: hil run scenarios/logi/release.yaml --seed 42"));
  EXPECT_THAT(xml, HasSubstr("<system-out>seed 7\n"));
  EXPECT_THAT(xml, HasSubstr("ok      steps line 5: speed 50"));
  expect_well_escaped(xml);
}

TEST(ReportJunit, ASkippedRunIsASkippedTestcaseAndNoFailure) {
  const std::string xml = junit_xml({entry(skipped()), entry(failed_step())});
  EXPECT_THAT(xml, HasSubstr("tests=\"2\" failures=\"1\" errors=\"0\" skipped=\"1\""));
  EXPECT_THAT(xml,
              HasSubstr("name=\"manual-keepalive\" time=\"0.000\" "
                        "file=\"scenarios/logi/keepalive.yaml\">\n    <skipped message=\"it "
                        "sets hil&#39;s reference client&#39;s keepalive\"/>\n    <system-out>"));
}

TEST(ReportJunit, HostileTextStaysInsideItsElement) {
  auto o = failed_expectation();
  o.name = "a<b>&\"c\"";
  o.expectations[0].message = "</failure><x>& \x01 \xFF";
  o.expectations[0].evidence = {frame(1, "to_car", "delivered", "]]></system-out>")};
  const std::string xml = junit_xml({entry(o)});
  EXPECT_THAT(xml, HasSubstr("name=\"a&lt;b&gt;&amp;&quot;c&quot;\""));
  EXPECT_THAT(xml, Not(HasSubstr("</failure><x>")));
  expect_well_escaped(xml);
  EXPECT_EQ(xml.find('\x01'), std::string::npos);
}

TEST(ReportJunit, IsXmlThatAParserAccepts) {
  if (!hil::test::python_xml_available()) GTEST_SKIP() << "python3 is not installed";
  auto o = failed_expectation();
  o.name = "a<b>&\"c\"";
  o.expectations[0].message = "</failure><x>& \x01 \xFF";
  auto entries = all_four();
  entries.push_back(entry(o));
  const auto path = std::filesystem::temp_directory_path() / "hil_report_test_junit.xml";
  {
    std::ofstream out(path);
    out << junit_xml(entries);
  }
  EXPECT_EQ(hil::test::python_checks_junit(path, 5), 0);
  std::filesystem::remove(path);
}

TEST(ReportFolder, FolderNamesAreSafeAndUnique) {
  auto a = passing();
  a.name = "../etc/passwd";
  auto b = passing();
  b.file = "other.yaml";
  std::vector<ReportEntry> entries{entry(a), entry(passing()), entry(b), entry(failed_step(), 0, 2),
                                   entry(failed_step(), 1, 2)};
  report_folders(entries);
  EXPECT_EQ(entries[0].folder, "_etc_passwd");
  EXPECT_EQ(entries[1].folder, "drive-forward");
  EXPECT_EQ(entries[2].folder, "drive-forward-2");
  EXPECT_EQ(entries[3].folder, "rejected-mode-1");
  EXPECT_EQ(entries[4].folder, "rejected-mode-2");
}

// The page with every <script> element taken out: what is left is markup
// whose text must be escaped.
std::string without_scripts(std::string page) {
  for (auto open = page.find("<script"); open != std::string::npos; open = page.find("<script")) {
    const auto close = page.find("</script>", open);
    if (close == std::string::npos) break;
    page.erase(open, close + 9 - open);
  }
  return page;
}

// The data the playback script reads from a run page.
nlohmann::json playback_data(const std::string& page) {
  const std::string open = "<script id=\"pb-data\" type=\"application/json\">";
  const auto from = page.find(open);
  if (from == std::string::npos) return nullptr;
  const auto to = page.find("</script>", from);
  return nlohmann::json::parse(page.substr(from + open.size(), to - from - open.size()), nullptr,
                               false);
}

TEST(ReportFolder, EachRunGetsItsPageTimelineAndTrajectory) {
  const auto dir = std::filesystem::temp_directory_path() / "hil_report_test_dir";
  std::filesystem::remove_all(dir);
  write_report_dir(dir.string(), all_four());

  const std::string index = read_file(dir / "index.html");
  EXPECT_THAT(index, HasSubstr("1 passed, 3 failed"));
  EXPECT_THAT(index, HasSubstr("href=\"release-sends-stop/index.html\""));
  EXPECT_THAT(index, HasSubstr("href=\"broken/index.html\""));

  const auto run = dir / "release-sends-stop";
  const std::string page = read_file(run / "index.html");
  expect_contains(
      page, {"<span class=\"fail\">FAIL</span>", "hil run scenarios/logi/release.yaml --seed 42",
             "<p>window: 5.000 s .. 5.300 s</p>", "car received  LOGI:MV:STOP:A1#",
             "<img src=\"trajectory.svg\"", "function filterTimeline"});
  // Nothing from outside the folder: it must open from a CI artifact.
  EXPECT_THAT(page, Not(HasSubstr("http")));
  expect_well_escaped(without_scripts(page.substr(page.find("<body>"))));

  EXPECT_THAT(read_file(run / "trajectory.svg"), HasSubstr("<svg"));
  const std::string ndjson = read_file(dir / "drive-forward" / "timeline.ndjson");
  EXPECT_EQ(ndjson, passing().timeline.to_ndjson());
  EXPECT_THAT(read_file(dir / "drive-forward" / "index.html"), HasSubstr("data-source=\"wire\""));
  std::filesystem::remove_all(dir);
}

TEST(ReportPlayback, RunPagesDrawWithTheLiveViewsScriptAndCarryTheRun) {
  auto o = passing();
  o.arena = sim::default_warehouse_arena();
  sim::Trajectory t;
  t.vehicle = "logi0";
  t.length_m = 0.3;
  t.width_m = 0.25;
  for (int i = 0; i <= 100; ++i)
    t.samples.push_back({milliseconds(i * 10), sim::Pose{1.0 + 0.001 * i, 0.5, 0.0}});
  t.marks.push_back({milliseconds(600), {1.06, 0.5}, sim::MarkKind::station, "station 001"});
  o.trajectories = {t};
  o.timeline.add(frame(130, "to_car", "sent", "LOGI:MV:STOP:A1#"));
  o.timeline.add(frame(140, "to_client", "delivered", "</script><b>", false));
  o.timeline.add(milliseconds(150), link::FaultKind::corrupt,
                 {{"dir", "to_client"}, {"rule", "bad-cs"}, {"detail", "checksum"}});
  o.timeline.add(milliseconds(160), ClientKind::notice, {{"text", "parse error"}});

  const std::string page = run_page_html(entry(o));
  // The same drawing as `hil mock --view`, inline: the page opens offline.
  EXPECT_THAT(page, HasSubstr(std::string(view::drawing_script())));
  EXPECT_THAT(page, HasSubstr("id=\"pb-slider\""));
  // A frame's text cannot end the data's script element early.
  EXPECT_THAT(page, Not(HasSubstr("</script><b>")));

  const auto data = playback_data(page);
  ASSERT_TRUE(data.is_object()) << "the playback data is not JSON";
  EXPECT_DOUBLE_EQ(data["run_ms"].get<double>(), 12345.0);
  EXPECT_EQ(data["arena"]["stations"].size(), o.arena.tags.size());
  ASSERT_EQ(data["cars"].size(), 1U);
  const auto& car = data["cars"][0];
  EXPECT_EQ(car["name"], "logi0");
  ASSERT_EQ(car["samples"].size(), 101U);
  EXPECT_EQ(car["samples"][50], nlohmann::json({500.0, 1.05, 0.5, 0.0}));
  EXPECT_EQ(car["marks"][0][3], "station");
  // Frames as the receiver got them (after faults), not as they were sent.
  ASSERT_EQ(data["frames"].size(), 2U);
  EXPECT_EQ(data["frames"][0],
            nlohmann::json({125.0, "to_car", "MV:STOP", "LOGI:SP:050:D7#", true}));
  EXPECT_EQ(data["frames"][1][3], "</script><b>");
  EXPECT_EQ(data["frames"][1][4], false);
  ASSERT_EQ(data["faults"].size(), 1U);
  EXPECT_EQ(data["faults"][0],
            nlohmann::json({150.0, "to_client", "corrupt", "bad-cs", "checksum"}));
  ASSERT_EQ(data["events"].size(), 1U);
  EXPECT_EQ(data["events"][0][1], "client");
}

TEST(ReportPlayback, LongRunsAreThinnedButKeepTheirLastPose) {
  auto o = passing();
  sim::Trajectory t;
  t.vehicle = "car";
  for (int i = 0; i < 50001; ++i)
    t.samples.push_back({milliseconds(i * 10), sim::Pose{0.00001 * i, 1.0, 90.0}});
  o.trajectories = {t};
  const auto data = playback_data(run_page_html(entry(o)));
  ASSERT_TRUE(data.is_object());
  const auto& samples = data["cars"][0]["samples"];
  EXPECT_LE(samples.size(), 12001U);
  EXPECT_GE(samples.size(), 10000U);
  EXPECT_DOUBLE_EQ(samples.back()[0].get<double>(), 500000.0);
  EXPECT_DOUBLE_EQ(samples.back()[1].get<double>(), 0.5);
}

TEST(ReportFolder, SaysWhichPathCannotBeWritten) {
  const auto file = std::filesystem::temp_directory_path() / "hil_report_test_not_a_dir";
  {
    std::ofstream out(file);
    out << "x";
  }
  try {
    write_report_dir((file / "sub").string(), all_four());
    ADD_FAILURE() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("hil_report_test_not_a_dir"));
  }
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace hil::harness
