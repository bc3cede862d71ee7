#pragma once
// What `hil run` tells people and CI about finished runs: the console table
// with each failure's evidence and repro command, JUnit XML, and a report
// folder of HTML pages, NDJSON timelines and SVG trajectories.

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "harness/outcome.hpp"

namespace hil::harness {

/// One run of one scenario as the reports see it. Runs of the same scenario
/// (--repeat) sit next to each other, in repeat order.
struct ReportEntry {
  ScenarioOutcome outcome;
  int repeat = 0;   ///< 0-based index of this run among the scenario's runs
  int repeats = 1;  ///< how many times the scenario ran
  /// The run's folder under the report directory ("release-stop-2"); empty:
  /// made from the name by report_folders().
  std::string folder;
};

/// A scenario's verdict over all its runs: a scenario that both passed and
/// failed is flaky, and counts as failed; one not run (its runs are all
/// skipped) is skipped, and fails nothing.
enum class Verdict { pass, fail, flaky, skip };
const char* to_string(Verdict verdict);  ///< "PASS", "FAIL", "FLAKY", "SKIP"

/// One verdict per scenario (a group of entries starts at each repeat 0),
/// in entry order.
struct ScenarioSummary {
  std::string file;
  std::string name;
  Verdict verdict = Verdict::pass;
  int runs = 0;
  int failed_runs = 0;
};
std::vector<ScenarioSummary> summarize(const std::vector<ReportEntry>& entries);

/// "N passed, M failed", counting scenarios (a flaky one as failed), with
/// ", K skipped" when some were not run.
std::string summary_line(const std::vector<ReportEntry>& entries);

struct ConsoleOptions {
  bool color = false;       ///< ANSI colours (only for a terminal without NO_COLOR)
  std::size_t width = 100;  ///< the table's lines are cut to this many columns
};

/// Whether to colour output written to `fd`: a terminal, and NO_COLOR unset.
bool want_color(int fd);
/// The width of the terminal on `fd`, or `fallback` when it is not one.
std::size_t terminal_width(int fd, std::size_t fallback = 100);

/// The table (one row per run), then a block per failed run (file, each
/// failed step or expectation with its message and evidence, the repro
/// command), then flaky scenarios, then the summary line.
void write_console(std::ostream& out, const std::vector<ReportEntry>& entries,
                   const ConsoleOptions& options = {});

/// The failure block of one run, without colour: what JUnit's <failure>
/// holds and the console prints.
std::string failure_text(const ScenarioOutcome& outcome);

/// One timeline record for a person: "   5.000 s  wire    car received  LOGI:MV:STOP:..#".
std::string format_record(const Record& record);

/// What a record says, without its time and source ("car received  LOGI:MV:STOP:..#").
std::string describe_record(const Record& record);

/// "12.345 s": a run's time with three decimals.
std::string format_seconds(Duration d);

/// A JUnit XML document: one <testsuite name="hil">, one <testcase> per run.
std::string junit_xml(const std::vector<ReportEntry>& entries);

/// A <testcase>'s classname: the scenario file's folder with dots
/// ("scenarios.logi"), else its first tag, else "hil".
std::string junit_classname(const std::string& file, const std::vector<std::string>& tags);

/// Fills each entry's empty `folder`: the scenario's name made safe for a
/// file name, "-<repeat>" (from 1) when it ran more than once, and "-2",
/// "-3"... when two scenarios share a name.
void report_folders(std::vector<ReportEntry>& entries);

/// Writes DIR/index.html (every run, with links), DIR/results.json (every
/// run's verdict, for tools) and, per run,
/// DIR/<folder>/{index.html, timeline.ndjson, trajectory.svg}. Creates the
/// folders; throws std::runtime_error naming the path that cannot be written.
void write_report_dir(const std::string& dir, std::vector<ReportEntry> entries);

/// The page of one run (what DIR/<folder>/index.html holds).
std::string run_page_html(const ReportEntry& entry);

/// One run as DIR/results.json keeps it, for tools that read a finished
/// report folder (`hil report merge` joins the folders of CI shards).
struct RunResult {
  std::string file;  ///< the scenario file as the run named it
  std::string name;
  std::vector<std::string> tags;
  int repeat = 0;  ///< 0-based
  int repeats = 1;
  std::uint64_t seed = 0;
  Verdict verdict = Verdict::pass;  ///< pass, fail or skip (a run is never flaky)
  double run_time_s = 0;            ///< simulated (or real) time the run covered
  double wall_seconds = 0;
  bool real_time = false;
  std::string folder;         ///< the run's folder under the report directory; "" none
  std::string first_failure;  ///< or why it was skipped
  std::string failure_text;   ///< failure_text() of a failed run
  std::string repro_command;
  friend bool operator==(const RunResult&, const RunResult&) = default;
};

/// The run as results.json keeps it.
RunResult run_result(const ReportEntry& entry);

/// DIR/results.json: {"format": "hil-results", "version": 1, "runs": [...]},
/// one object per run with the fields of RunResult ("verdict": "pass",
/// "fail" or "skip").
std::string results_json(const std::vector<RunResult>& runs);

/// The runs of a results.json text. Throws std::runtime_error saying what
/// is wrong (not JSON, not hil's results, a run without its file...).
std::vector<RunResult> parse_results_json(const std::string& text);

/// DIR/index.html: `heading`, then a row per run linking its folder (a run
/// without a folder has no link).
std::string index_html(const std::vector<RunResult>& runs, const std::string& heading);

}  // namespace hil::harness
