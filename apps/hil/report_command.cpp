// hil report merge: the JUnit files or report folders of CI shards (hil run
// --shard K/N) joined into one JUnit file and one report folder, checked
// for failed runs and for scenarios no shard ran or two shards ran. Exit 0
// all passed and (with --expect) all present once; 1 otherwise; 2 bad usage
// or an input that cannot be read. The joining is harness/report_merge.hpp.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "apps/hil/cli_common.hpp"
#include "harness/atomic_file.hpp"
#include "harness/report.hpp"
#include "harness/report_merge.hpp"
#include "harness/scenario_search.hpp"
#include "harness/scenario_yaml.hpp"

namespace hil::apps {
// Named, so its helpers do not meet hil run's in a unity build.
namespace report_merge_cli {
namespace {

namespace fs = std::filesystem;

struct MergeArgs {
  std::vector<std::string> inputs;
  std::string junit;
  std::string report_dir;
  std::vector<std::string> expect;
  std::vector<std::string> tags;
  std::vector<std::string> exclude_tags;
};

// An input that cannot be read: exit 2 with its path and why.
struct UnreadableInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UnreadableInput(path.string() + ": cannot be read");
  std::ostringstream out;
  out << in.rdbuf();
  if (in.bad()) throw UnreadableInput(path.string() + ": cannot be read");
  return out.str();
}

harness::MergeInput read_input(const std::string& arg) {
  std::error_code ec;
  const fs::path path(arg);
  if (fs::is_directory(path, ec)) {
    const fs::path results = path / "results.json";
    if (!fs::exists(results, ec)) {
      throw UnreadableInput(arg +
                            ": a folder without results.json (not a report folder of hil run "
                            "--report-dir)");
    }
    return {arg, harness::MergeInput::Kind::results, read_text(results)};
  }
  if (!fs::exists(path, ec)) throw UnreadableInput(arg + ": no such file or folder");
  return {arg, harness::MergeInput::Kind::junit, read_text(path)};
}

// The scenario files hil run would run for these paths and tags. A file
// that does not load stays in, as in hil run.
std::vector<std::string> expected_files(const MergeArgs& args) {
  std::vector<std::string> found;
  try {
    found = harness::find_scenario_files(args.expect).files;
  } catch (const harness::ScenarioSearchError& e) {
    throw UnreadableInput(std::string("--expect ") + e.what());
  }
  std::vector<std::string> out;
  for (const auto& file : found) {
    if (!args.tags.empty() || !args.exclude_tags.empty()) {
      try {
        const auto scenario = harness::load_scenario(file, {}, {true});
        if (!args.tags.empty() && !harness::has_any_tag(scenario.tags, args.tags)) continue;
        if (harness::has_any_tag(scenario.tags, args.exclude_tags)) continue;
      } catch (const std::exception&) {
        // Does not load: hil run keeps it, whatever the tags.
      }
    }
    out.push_back(file);
  }
  return out;
}

// The merged report folder: every input's run folders, renamed where two
// shards used the same name, then index.html and results.json of all runs.
void write_merged_dir(const MergeArgs& args, const harness::MergeResult& merged) {
  const fs::path root(args.report_dir);
  std::error_code ec;
  fs::create_directories(root, ec);
  if (ec) throw std::runtime_error("cannot create " + root.string() + ": " + ec.message());
  for (const auto& copy : merged.copies) {
    const fs::path from = fs::path(args.inputs[copy.input]) / copy.from;
    const fs::path to = root / copy.to;
    fs::remove_all(to, ec);
    fs::copy(from, to, fs::copy_options::recursive | fs::copy_options::overwrite_existing, ec);
    if (ec) {
      throw std::runtime_error("cannot copy " + from.string() + " to " + to.string() + ": " +
                               ec.message());
    }
  }
  harness::write_file_atomically((root / "results.json").string(),
                                 harness::results_json(merged.runs));
  harness::write_file_atomically((root / "index.html").string(),
                                 harness::index_html(merged.runs, merged.summary()));
}

int merge(const MergeArgs& args) {
  std::vector<harness::MergeInput> inputs;
  harness::MergeOptions options;
  harness::MergeResult merged;
  try {
    for (const auto& arg : args.inputs)
      inputs.push_back(read_input(arg));
    if (!args.expect.empty()) options.expected = expected_files(args);
    merged = harness::merge_reports(inputs, options);
  } catch (const UnreadableInput& e) {
    std::cerr << "hil report merge: " << e.what() << '\n';
    return 2;
  } catch (const harness::MergeInputError& e) {
    std::cerr << "hil report merge: " << e.what() << '\n';
    return 2;
  }
  int status = merged.ok() ? 0 : 1;
  try {
    harness::write_file_atomically(args.junit, merged.junit);
    if (!args.report_dir.empty()) write_merged_dir(args, merged);
  } catch (const std::exception& e) {
    std::cerr << "hil report merge: " << e.what() << '\n';
    status = 1;
  }
  for (const auto& line : merged.problems())
    std::cout << line << '\n';
  std::cout << merged.runs.size() << " runs from " << inputs.size() << " inputs";
  if (options.expected) std::cout << ", " << options.expected->size() << " scenarios expected";
  std::cout << '\n' << merged.summary() << '\n';
  if (!args.report_dir.empty())
    std::cout << "report: " << (fs::path(args.report_dir) / "index.html").string() << '\n';
  return status;
}

}  // namespace
}  // namespace report_merge_cli

void register_report(CLI::App& app, std::function<int()>& run) {
  auto* report = app.add_subcommand("report", "Work with the results of hil run");
  report->require_subcommand(1);
  using namespace report_merge_cli;
  auto args = std::make_shared<MergeArgs>();
  auto* cmd = report->add_subcommand(
      "merge",
      "Join the JUnit files or report folders of CI shards (hil run --shard K/N) into one, "
      "checking every scenario ran once");
  cmd->add_option("inputs", args->inputs,
                  "Each shard's JUnit file (hil run --junit) or report folder (hil run "
                  "--report-dir)")
      ->required();
  cmd->add_option("--junit", args->junit, "Write the joined JUnit XML to FILE")
      ->type_name("FILE")
      ->required();
  cmd->add_option("--report-dir", args->report_dir,
                  "Write one report folder with every run (from report-folder inputs) and one "
                  "index.html to DIR")
      ->type_name("DIR");
  cmd->add_option("--expect", args->expect,
                  "Every scenario file under DIR (found as hil run finds them) must be in "
                  "exactly one input (repeatable)")
      ->type_name("DIR")
      ->allow_extra_args(false);
  cmd->add_option("--tags", args->tags, "With --expect: only scenarios with any of these tags")
      ->type_name("TAGS")
      ->delimiter(',')
      ->allow_extra_args(false);
  cmd->add_option("--exclude-tags", args->exclude_tags,
                  "With --expect: leave out scenarios with any of these tags")
      ->type_name("TAGS")
      ->delimiter(',')
      ->allow_extra_args(false);
  cmd->footer(
      "Example (after hil run scenarios/logi --shard K/3 --report-dir shard-K, K = 1..3):\n"
      "  hil report merge --expect scenarios/logi --junit hil.xml --report-dir hil-report \\\n"
      "      shard-1 shard-2 shard-3\n"
      "Exit status: 0 every run passed (or was skipped) and, with --expect, every expected\n"
      "scenario is in exactly one input; 1 a run failed, or a scenario is missing or in two\n"
      "inputs (each is named, with its inputs); 2 a malformed command line or an input that\n"
      "cannot be read.");
  cmd->callback([&run, args] { run = [args] { return merge(*args); }; });
}

}  // namespace hil::apps
