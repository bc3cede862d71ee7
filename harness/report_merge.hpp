#pragma once
// `hil report merge`: the results of N CI shards (`hil run --shard K/N`)
// joined into one JUnit document and one list of runs for one report
// folder, with the checks a sharded gate needs: every run passed, every
// expected scenario ran in exactly one shard. Pure: the caller reads the
// inputs and writes the outputs (apps/hil/report_command.cpp).

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/report.hpp"

namespace hil::harness {

/// One shard's results as read from disk.
struct MergeInput {
  enum class Kind { junit, results };
  std::string source;  ///< the path as named, for messages
  Kind kind = Kind::junit;
  std::string text;  ///< the JUnit XML, or the report folder's results.json
};

/// An input that cannot be read as what it claims to be.
class MergeInputError : public std::runtime_error {
 public:
  MergeInputError(std::size_t input, const std::string& message)
      : std::runtime_error(message), input_(input) {}
  std::size_t input() const { return input_; }

 private:
  std::size_t input_;
};

struct MergeOptions {
  /// Every scenario file the shards were to run (as `hil run` names them,
  /// "scenarios/logi/x.yaml"); nullopt: not checked. An expected file
  /// matches a run's file when the paths are equal or one ends with the
  /// other ("/builds/x/scenarios/logi/x.yaml" and "scenarios/logi/x.yaml").
  std::optional<std::vector<std::string>> expected;
};

/// A report folder's run folder copied into the merged folder.
struct FolderCopy {
  std::size_t input = 0;
  std::string from;  ///< the folder's name in its input
  std::string to;    ///< its name in the merged folder
};

/// A scenario file found in more than one input, or a failed run.
struct MergeFinding {
  std::string file;
  std::string name;
  std::vector<std::string> sources;  ///< the inputs it came from
};

struct MergeResult {
  std::vector<RunResult> runs;          ///< every run, input by input; folders renamed
  std::vector<std::size_t> run_inputs;  ///< runs[i] came from inputs[run_inputs[i]]
  std::vector<FolderCopy> copies;
  std::string junit;  ///< one <testsuite name="hil">, every <testcase>
  std::vector<MergeFinding> failed;
  std::vector<std::string> missing;  ///< expected files in no input
  std::vector<MergeFinding> doubled;
  bool ok() const { return failed.empty() && missing.empty() && doubled.empty(); }
  /// "12 passed, 1 failed", counting scenario files, with ", 2 missing"
  /// and ", 1 doubled" when some are.
  std::string summary() const;
  /// One line per failed run, missing scenario and doubled scenario.
  std::vector<std::string> problems() const;
};

/// Joins the inputs in the order given. Throws MergeInputError for an input
/// that is not JUnit XML or hil's results.json, or a test case without the
/// scenario's file.
MergeResult merge_reports(const std::vector<MergeInput>& inputs, const MergeOptions& options = {});

/// A scenario file path as the merge compares them: normalised, '/'.
std::string normal_scenario_path(const std::string& path);

}  // namespace hil::harness
