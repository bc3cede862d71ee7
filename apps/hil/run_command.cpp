// hil run: runs scenario files (in parallel), prints the table with every
// failure's evidence and the command that repeats it, and writes JUnit XML
// and a report folder for CI. Exit 0 all passed, 1 any failed, 2 bad usage.

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>
#include <set>
#include <thread>

#include "apps/hil/cli_common.hpp"
#include "base/duration.hpp"
#include "config/error.hpp"
#include "harness/atomic_file.hpp"
#include "harness/exec_client.hpp"
#include "harness/report.hpp"
#include "harness/runner.hpp"
#include "harness/scenario_search.hpp"
#include "harness/scenario_yaml.hpp"
#include "harness/shard.hpp"
#include "link/capture/probe_capture.hpp"
#include "link/faults/profile_yaml.hpp"
#include "mocks/avr/firmware_source.hpp"

namespace hil::apps {
namespace {

namespace fs = std::filesystem;
using harness::ReportEntry;
using harness::Scenario;
using harness::ScenarioOutcome;

struct RunArgs {
  std::vector<std::string> paths;
  std::string junit;
  std::string report_dir;
  std::optional<std::uint64_t> seed;
  int repeat = 1;
  std::vector<std::string> tags;
  std::vector<std::string> exclude_tags;
  std::optional<std::string> client_exec;
  std::string replay;         ///< a probe capture every scenario's car plays; empty: none
  std::string unmatched;      ///< with replay: mock or silent
  std::string sketch;         ///< a sketch every Arduino scenario's car runs; empty: none
  std::string elf;            ///< or a firmware image
  std::string pins;           ///< with sketch or elf: the pin map file
  std::string board_startup;  ///< with sketch or elf: the board's start-up ("0ms"); empty: 66 ms
  std::string slack;          ///< as written ("100ms"); empty: the runner's default
  std::vector<std::string> sets;
  std::string jobs = "auto";  ///< -j as written: N, or auto (parse_jobs())
  bool list = false;
  bool verbose = false;
  bool allow_outside_paths = false;
  std::string shard;  ///< --shard K/N as written; empty: every selected scenario
};

// For the repro command: a word the shell passes through unchanged.
std::string shell_quote(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 ||
           std::string_view("_-./=:,+@%").find(c) != std::string_view::npos;
  });
  if (plain) return word;
  std::string out = "'";
  for (const char c : word)
    out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// "--sketch robot.ino", "--elf robot.elf": how the firmware was given.
std::string firmware_given(const RunArgs& args) {
  return args.sketch.empty() ? "--elf " + args.elf : "--sketch " + args.sketch;
}

std::string repro_command(const RunArgs& args, const std::string& file,
                          std::optional<std::uint64_t> seed) {
  std::string out = "hil run " + shell_quote(file);
  if (seed) out += " --seed " + std::to_string(*seed);
  for (const auto& s : args.sets)
    out += " --set " + shell_quote(s);
  if (args.client_exec) out += " --client-exec " + shell_quote(*args.client_exec);
  if (!args.replay.empty()) out += " --replay " + shell_quote(args.replay);
  if (!args.unmatched.empty()) out += " --unmatched " + args.unmatched;
  if (!args.sketch.empty()) out += " --sketch " + shell_quote(args.sketch);
  if (!args.elf.empty()) out += " --elf " + shell_quote(args.elf);
  if (!args.pins.empty()) out += " --pins " + shell_quote(args.pins);
  if (!args.board_startup.empty()) out += " --board-startup " + shell_quote(args.board_startup);
  if (args.allow_outside_paths) out += " --allow-outside-paths";
  if (!args.slack.empty()) out += " --slack " + shell_quote(args.slack);
  return out;
}

struct Planned {
  std::string file;
  std::optional<Scenario> scenario;
  std::string error;  ///< why it did not load
};

std::string joined(const std::vector<std::string>& words, const char* separator = ", ") {
  std::string out;
  for (const auto& w : words)
    out += (out.empty() ? "" : separator) + w;
  return out;
}

// The scenario files named by the arguments, sorted; nullopt (and a message
// on stderr) for a path that does not exist.
std::optional<std::vector<std::string>> find_files(const RunArgs& args) {
  try {
    auto found = harness::find_scenario_files(args.paths);
    if (args.verbose) {
      for (const auto& f : found.not_scenarios)
        std::cerr << "hil run: skipped " << f
                  << " (no top-level car: and steps:, not a scenario)\n";
    }
    return std::move(found.files);
  } catch (const harness::ScenarioSearchError& e) {
    std::cerr << "hil run: " << e.what() << '\n';
    return std::nullopt;
  }
}

// The command an external client of this scenario runs, as written (the
// placeholders are filled in per run); nullopt for a reference client.
std::optional<std::string> client_command(const RunArgs& args, const Scenario& scenario) {
  if (args.client_exec) return *args.client_exec;
  if (const auto* exec = std::get_if<harness::ExecClient>(&scenario.client)) return exec->command;
  return std::nullopt;
}

ScenarioOutcome load_failure(const Planned& p, const RunArgs& args) {
  ScenarioOutcome o;
  o.file = p.file;
  o.name = fs::path(p.file).stem().string();
  o.error = p.error;
  o.repro_command = repro_command(args, p.file, std::nullopt);
  return o;
}

// The --set values by name; nullopt (and a message) for one without '='.
std::optional<std::map<std::string, std::string>> variable_overrides(const RunArgs& args) {
  std::map<std::string, std::string> overrides;
  for (const auto& s : args.sets) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) {
      std::cerr << "hil run: --set " << s << ": expected name=value\n";
      return std::nullopt;
    }
    overrides[s.substr(0, eq)] = s.substr(eq + 1);
  }
  return overrides;
}

// Each file loaded, those without the wanted tags left out.
std::vector<Planned> load_plan(const RunArgs& args, const std::vector<std::string>& files,
                               const std::map<std::string, std::string>& overrides) {
  std::vector<Planned> plan;
  for (const auto& file : files) {
    Planned p{file, std::nullopt, {}};
    try {
      p.scenario =
          harness::load_scenario(file, overrides, harness::LoadOptions{args.allow_outside_paths});
    } catch (const config::ConfigError& e) {
      p.error = e.what();
    } catch (const std::exception& e) {
      p.error = file + ": " + e.what();
    }
    if (p.scenario) {
      if (!args.tags.empty() && !harness::has_any_tag(p.scenario->tags, args.tags)) continue;
      if (harness::has_any_tag(p.scenario->tags, args.exclude_tags)) continue;
    }
    // A file that does not load stays in, whatever the tags: a gate must not
    // pass because a broken file was silently left out.
    plan.push_back(std::move(p));
  }
  return plan;
}

// --shard K/N: the planned files of shard K, each weighed by its expected
// time (harness/shard.hpp); a file that did not load has a nominal weight.
std::vector<Planned> shard_plan(const RunArgs& args, std::vector<Planned> plan) {
  std::vector<harness::ShardItem> items;
  for (const auto& p : plan) {
    const double weight_s =
        p.scenario ? std::chrono::duration<double>(harness::expected_duration(*p.scenario)).count()
                   : harness::kShardNominalWeightS;
    items.push_back({harness::shard_key(p.file, args.paths), p.file, weight_s});
  }
  std::vector<Planned> out;
  for (const std::size_t i : harness::shard_members(items, *harness::parse_shard(args.shard)))
    out.push_back(std::move(plan[i]));
  return out;
}

// --list: each scenario with its tags and any program it would start.
int list_plan(const RunArgs& args, const std::vector<Planned>& plan) {
  bool all_load = true;
  for (const auto& p : plan) {
    if (p.scenario) {
      std::cout << p.file << "  " << p.scenario->name;
      if (!p.scenario->tags.empty()) std::cout << "  [" << joined(p.scenario->tags) << ']';
      std::cout << '\n';
      // Every program a run would start, before anything is started.
      if (const auto command = client_command(args, *p.scenario))
        std::cout << "  client exec: " << *command << '\n';
    } else {
      all_load = false;
      std::cout << p.file << "  does not load: " << p.error << '\n';
    }
  }
  return all_load ? 0 : 1;
}

// One run of a planned file: which, and with which seed.
struct Task {
  std::size_t plan_index;
  std::optional<std::uint64_t> seed;
};

// The runs, one entry each in the table's order (file, then repeat); each
// entry knows its folder before it runs so the runner can put files there.
struct Batch {
  std::vector<ReportEntry> entries;
  std::vector<Task> tasks;
};

Batch make_batch(const RunArgs& args, const std::vector<Planned>& plan) {
  Batch batch;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const auto& p = plan[i];
    if (!p.scenario) {
      ReportEntry e;
      e.outcome = load_failure(p, args);
      batch.entries.push_back(std::move(e));
      batch.tasks.push_back(Task{i, std::nullopt});
      continue;
    }
    const std::optional<std::uint64_t> base = args.seed ? args.seed : p.scenario->seed;
    for (int r = 0; r < args.repeat; ++r) {
      ReportEntry e;
      e.outcome.file = p.file;
      e.outcome.name = p.scenario->name;
      e.repeat = r;
      e.repeats = args.repeat;
      batch.entries.push_back(std::move(e));
      batch.tasks.push_back(
          Task{i, base ? std::optional<std::uint64_t>(*base + static_cast<std::uint64_t>(r))
                       : std::nullopt});
    }
  }
  if (!args.report_dir.empty()) harness::report_folders(batch.entries);
  return batch;
}

// How many runs go at once. `-j N`: N, of whatever kind. `-j auto` (the
// default): a run in virtual time keeps a core busy, so at most one per
// core; a run in real time mostly waits on its clock and its client, so
// harness::kRealTimeRunsPerCore per core, virtual-time ones among them.
struct JobLimits {
  std::size_t total = 1;
  std::size_t virtual_time = 1;
};

// -j's value: "auto", or N >= 1; nullopt for anything else.
std::optional<std::size_t> parse_jobs(const std::string& text) {
  if (text == "auto") return std::size_t{0};
  std::size_t used = 0;
  try {
    const long n = std::stol(text, &used);
    if (used == text.size() && n >= 1 && n <= 1024) return static_cast<std::size_t>(n);
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

JobLimits job_limits(const std::string& jobs, bool any_real_time) {
  const std::size_t cores = std::max(1U, std::thread::hardware_concurrency());
  if (const std::size_t n = parse_jobs(jobs).value_or(0); n > 0) return {n, n};
  return {any_real_time ? cores * harness::kRealTimeRunsPerCore : cores, cores};
}

// Runs a batch on worker threads, printing what the runs start and, with
// -v, each run as it finishes. Runs start longest first (by their
// scenarios' expected durations, harness::expected_duration()), so the
// batch does not end waiting on one long run started last; the table keeps
// the files' order.
class BatchRunner {
 public:
  BatchRunner(const RunArgs& args, const std::vector<Planned>& plan, Batch& batch,
              std::optional<mocks::ReplaySpec> replay, std::optional<mocks::AvrConfig> firmware)
      : args_(args),
        plan_(plan),
        batch_(batch),
        replay_(std::move(replay)),
        firmware_(std::move(firmware)) {}

  void run() {
    plan_queue();
    const std::size_t threads_wanted = std::min(limits_.total, batch_.tasks.size());
    std::vector<std::thread> threads;
    for (std::size_t t = 1; t < threads_wanted; ++t)
      threads.emplace_back([this] { work(); });
    work();
    for (auto& t : threads)
      t.join();
  }

 private:
  // The tasks in the order they start, each marked real time or not, and
  // the limits -j sets for them.
  void plan_queue() {
    harness::RunOptions kind;
    kind.client_exec = args_.client_exec;
    std::vector<double> expected_s(batch_.tasks.size(), 0.0);
    real_time_.assign(batch_.tasks.size(), false);
    for (std::size_t k = 0; k < batch_.tasks.size(); ++k) {
      const auto& p = plan_[batch_.tasks[k].plan_index];
      if (!p.scenario) continue;
      real_time_[k] = harness::runs_in_real_time(*p.scenario, kind);
      expected_s[k] =
          std::chrono::duration<double>(harness::expected_duration(*p.scenario)).count();
    }
    queue_.resize(batch_.tasks.size());
    std::iota(queue_.begin(), queue_.end(), std::size_t{0});
    std::stable_sort(queue_.begin(), queue_.end(),
                     [&](std::size_t a, std::size_t b) { return expected_s[a] > expected_s[b]; });
    limits_ = job_limits(args_.jobs,
                         std::find(real_time_.begin(), real_time_.end(), true) != real_time_.end());
  }

  // The next task this worker may start, longest first: a virtual-time run
  // only while fewer than limits_.virtual_time run. Waits while only such
  // runs are left and none may start; nullopt when none is left.
  std::optional<std::size_t> take() {
    std::unique_lock lock(queue_mutex_);
    for (;;) {
      const auto it = std::find_if(queue_.begin(), queue_.end(), [&](std::size_t k) {
        return real_time_[k] || running_virtual_ < limits_.virtual_time;
      });
      if (it != queue_.end()) {
        const std::size_t k = *it;
        queue_.erase(it);
        if (!real_time_[k]) ++running_virtual_;
        return k;
      }
      if (queue_.empty()) return std::nullopt;
      slot_freed_.wait(lock);
    }
  }

  void finished(std::size_t k) {
    {
      const std::lock_guard lock(queue_mutex_);
      if (!real_time_[k]) --running_virtual_;
    }
    slot_freed_.notify_all();
  }

  void work() {
    while (const auto k = take()) {
      const auto& p = plan_[batch_.tasks[*k].plan_index];
      auto& entry = batch_.entries[*k];
      if (p.scenario) entry.outcome = run_one(p, batch_.tasks[*k], entry);
      finished(*k);
      const std::size_t done = ++done_;
      if (args_.verbose) show_progress(done, p, entry);
    }
  }

  ScenarioOutcome run_one(const Planned& p, const Task& task, const ReportEntry& entry) {
    ScenarioOutcome outcome;
    try {
      outcome = harness::run_scenario(*p.scenario, options(p, task, entry));
    } catch (const std::exception& e) {
      outcome.error = std::string("the run stopped: ") + e.what();
    }
    if (outcome.file.empty()) outcome.file = p.file;
    if (outcome.name.empty()) outcome.name = p.scenario->name;
    if (outcome.tags.empty()) outcome.tags = p.scenario->tags;
    outcome.repro_command = repro_command(args_, p.file, outcome.seed);
    return outcome;
  }

  harness::RunOptions options(const Planned& p, const Task& task, const ReportEntry& entry) {
    harness::RunOptions options;
    options.seed = task.seed;
    options.client_exec = args_.client_exec;
    options.replay = replay_;
    options.firmware = firmware_;
    options.firmware_given = firmware_given(args_);
    // The emulated board's warnings (a firmware that never turns its UART
    // on, a simavr error), once each per scenario file.
    options.on_firmware_note = [this, file = p.file](const std::string& note) {
      const std::lock_guard lock(progress_);
      if (!shown_notes_.insert(file + '\n' + note).second) return;
      std::cerr << "hil run: " << file << ": firmware: " << note << '\n';
    };
    // A scenario may start one program, its declared client: print the
    // exact command line before it starts (once per scenario file).
    options.on_client_command = [this, file = p.file](const std::string& command) {
      const std::lock_guard lock(progress_);
      if (!shown_commands_.insert(file).second) return;
      std::cerr << "hil run: " << file << ": client exec: /bin/sh -c "
                << harness::shell_quote(command) << '\n';
    };
    if (!args_.slack.empty()) options.time_slack = parse_duration(args_.slack);
    if (!args_.report_dir.empty()) {
      const fs::path folder = fs::path(args_.report_dir) / entry.folder;
      std::error_code ec;
      fs::create_directories(folder, ec);
      if (!ec) options.work_dir = folder.string();
    }
    return options;
  }

  void show_progress(std::size_t finished, const Planned& p, const ReportEntry& entry) {
    const std::lock_guard lock(progress_);
    std::cerr << '[' << finished << '/' << batch_.tasks.size() << "] "
              << (entry.outcome.was_skipped() ? "SKIP "
                  : entry.outcome.passed()    ? "PASS "
                                              : "FAIL ")
              << entry.outcome.name;
    if (entry.repeats > 1) std::cerr << " #" << entry.repeat + 1;
    if (p.scenario) std::cerr << " (seed " << entry.outcome.seed << ')';
    std::cerr << '\n';
  }

  const RunArgs& args_;
  const std::vector<Planned>& plan_;
  Batch& batch_;
  std::optional<mocks::ReplaySpec> replay_;
  std::optional<mocks::AvrConfig> firmware_;
  JobLimits limits_;
  std::vector<bool> real_time_;      // per task: runs in real time
  std::vector<std::size_t> queue_;   // tasks not started yet, in start order
  std::size_t running_virtual_ = 0;  // virtual-time runs under way
  std::mutex queue_mutex_;
  std::condition_variable slot_freed_;
  std::atomic<std::size_t> done_{0};
  std::mutex progress_;
  std::set<std::string> shown_commands_;  // files whose client command was printed
  std::set<std::string> shown_notes_;     // file and firmware warning, printed
};

// The table on stdout, then JUnit XML and the report folder when asked
// for. Returns the exit status: 1 when anything failed (a skipped scenario
// did not) or a file could not be written.
int report_results(const RunArgs& args, const std::vector<ReportEntry>& entries) {
  harness::ConsoleOptions console;
  console.color = harness::want_color(STDOUT_FILENO);
  console.width = harness::terminal_width(STDOUT_FILENO, 100);
  harness::write_console(std::cout, entries, console);
  std::cout.flush();

  int status = 0;
  for (const auto& s : harness::summarize(entries))
    if (s.verdict == harness::Verdict::fail || s.verdict == harness::Verdict::flaky) status = 1;
  if (!args.junit.empty()) {
    // Atomically: a CI job that reads the file never sees half of it, and a
    // run stopped while writing leaves the previous file whole.
    try {
      harness::write_file_atomically(args.junit, harness::junit_xml(entries));
    } catch (const std::exception& e) {
      std::cerr << "hil run: " << e.what() << '\n';
      status = 1;
    }
  }
  if (!args.report_dir.empty()) {
    try {
      harness::write_report_dir(args.report_dir, entries);
      std::cout << "report: " << (fs::path(args.report_dir) / "index.html").string() << '\n';
    } catch (const std::exception& e) {
      std::cerr << "hil run: " << e.what() << '\n';
      status = 1;
    }
  }
  return status;
}

// --replay: the capture read once for every run; nullopt without it.
// Throws std::runtime_error with the reader's file:line message.
std::optional<mocks::ReplaySpec> load_replay(const RunArgs& args) {
  if (args.replay.empty()) {
    if (!args.unmatched.empty()) throw std::runtime_error("--unmatched needs --replay");
    return std::nullopt;
  }
  mocks::ReplaySpec replay;
  replay.path = args.replay;
  try {
    replay.capture = std::make_shared<const link::Capture>(link::read_capture(args.replay));
  } catch (const link::CaptureError& e) {
    throw std::runtime_error(std::string("--replay: ") + e.what());
  }
  if (!args.unmatched.empty()) replay.unmatched = *mocks::parse_unmatched(args.unmatched);
  return replay;
}

// --sketch or --elf (and --pins): the firmware built (or found in the
// cache) and checked once for every run; nullopt without them. Throws
// std::runtime_error naming the option: a sketch that does not compile
// carries the compiler's error lines.
std::optional<mocks::AvrConfig> load_firmware(const RunArgs& args) {
  if (args.sketch.empty() && args.elf.empty()) {
    if (!args.pins.empty()) throw std::runtime_error("--pins needs --sketch or --elf");
    if (!args.board_startup.empty())
      throw std::runtime_error("--board-startup needs --sketch or --elf");
    return std::nullopt;
  }
  mocks::avr::FirmwareSource source;
  source.sketch = args.sketch;
  source.elf = args.elf;
  source.pins = args.pins;
  if (!args.board_startup.empty()) source.startup_delay = parse_duration(args.board_startup);
  try {
    return mocks::avr::resolve_firmware(source);
  } catch (const config::ConfigError& e) {
    // A pin map file: the error names it, with the line.
    throw std::runtime_error(std::string(args.pins.empty() ? "the sketch's pin map" : "--pins") +
                             ": " + e.what());
  } catch (const std::exception& e) {
    // The build's or the image's error names the file.
    throw std::runtime_error(std::string(args.sketch.empty() ? "--elf: " : "--sketch: ") +
                             e.what());
  }
}

int run_scenarios(const RunArgs& args) {
  const auto overrides = variable_overrides(args);
  if (!overrides) return 2;
  std::optional<mocks::ReplaySpec> replay;
  std::optional<mocks::AvrConfig> firmware;
  try {
    if (!args.replay.empty() && !(args.sketch.empty() && args.elf.empty())) {
      throw std::runtime_error(std::string("--replay and ") +
                               (args.sketch.empty() ? "--elf" : "--sketch") +
                               " do not go together: the car either plays the capture or runs "
                               "the firmware");
    }
    replay = load_replay(args);
    firmware = load_firmware(args);
  } catch (const std::exception& e) {
    std::cerr << "hil run: " << e.what() << '\n';
    return 2;
  }
  const auto files = find_files(args);
  if (!files) return 2;
  if (files->empty()) {
    std::cerr << "hil run: no scenario files (YAML with top-level car: and steps:) in "
              << joined(args.paths, " ") << '\n';
    return 2;
  }
  std::vector<Planned> plan = load_plan(args, *files, *overrides);
  if (plan.empty()) {
    std::cerr << "hil run: no scenario has the tags " << joined(args.tags)
              << (args.exclude_tags.empty() ? "" : " without " + joined(args.exclude_tags)) << '\n';
    return 2;
  }
  if (!args.shard.empty()) {
    plan = shard_plan(args, std::move(plan));
    if (plan.empty()) {
      std::cerr << "hil run: shard " << args.shard << " has no scenarios (fewer scenarios than "
                << "shards); nothing to run\n";
      if (args.list) return 0;
    }
  }
  if (args.list) return list_plan(args, plan);
  Batch batch = make_batch(args, plan);
  BatchRunner(args, plan, batch, std::move(replay), std::move(firmware)).run();
  return report_results(args, batch.entries);
}

}  // namespace

void register_run(CLI::App& app, std::function<int()>& run) {
  auto args = std::make_shared<RunArgs>();
  auto* cmd = app.add_subcommand(
      "run", "Run scenario files against the reference clients or an external client");
  cmd->add_option("paths", args->paths,
                  "Scenario files, or folders searched for them (*.yaml with top-level car: and "
                  "steps:)")
      ->required();
  cmd->add_option("--junit", args->junit, "Write JUnit XML for CI to FILE")->type_name("FILE");
  cmd->add_option("--report-dir", args->report_dir,
                  "Write an HTML report, NDJSON timelines and SVG trajectories to DIR")
      ->type_name("DIR");
  cmd->add_option("--seed", args->seed, "Seed every scenario with N (overrides the files' seeds)")
      ->type_name("N");
  cmd->add_option(
         "--repeat", args->repeat,
         "Run each scenario N times, seeds S, S+1, ... from --seed or the file (else random): "
         "finds flaky scenarios")
      ->type_name("N")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--tags", args->tags, "Run only scenarios with any of these tags (a,b)")
      ->type_name("TAGS")
      ->delimiter(',')
      ->allow_extra_args(false);
  cmd->add_option("--exclude-tags", args->exclude_tags, "Leave out scenarios with any of these")
      ->type_name("TAGS")
      ->delimiter(',')
      ->allow_extra_args(false);
  cmd->add_option("--client-exec", args->client_exec,
                  "Run every scenario against this program instead of its client "
                  "({host} {port} {pty} {actions} ... as in docs/client-contract.md)")
      ->type_name("CMD");
  cmd->add_option("--replay", args->replay,
                  "Play every scenario's car from this probe capture (hil conform probe) instead "
                  "of its mock; scenarios of another car or profile are skipped")
      ->type_name("CAPTURE");
  cmd->add_option("--unmatched", args->unmatched,
                  "With --replay: a request the capture has no answer for gets the mock's answer "
                  "(mock, the default) or none (silent)")
      ->check(CLI::IsMember({"mock", "silent"}));
  auto* sketch =
      cmd->add_option("--sketch", args->sketch,
                      "Run every Arduino scenario's car as this sketch on the emulated ATmega328P "
                      "(built once, and cached); scenarios of other cars, and those that need the "
                      "behavioural mock, are skipped")
          ->type_name("FILE.ino");
  auto* elf = cmd->add_option("--elf", args->elf, "The same with a firmware image built already")
                  ->type_name("FILE.elf");
  sketch->excludes(elf);
  elf->excludes(sketch);
  cmd->add_option("--pins", args->pins,
                  "With --sketch or --elf: the pin map file (default: pins.yaml beside the "
                  "sketch, else the default wiring; docs/firmware.md)")
      ->type_name("FILE");
  cmd->add_option("--board-startup", args->board_startup,
                  "With --sketch or --elf: the time from the port opening to the sketch's first "
                  "instruction (default 66ms, the chip's own; the behavioural mock answers at "
                  "once, so scenarios written for it run on the board with 0ms)")
      ->type_name("D")
      ->check([](const std::string& text) {
        const auto d = parse_duration(text);
        return d && *d <= std::chrono::seconds(10)
                   ? std::string()
                   : "'" + text + "' is not a duration of at most 10s (e.g. 0ms, 66ms)";
      });
  cmd->add_option("--slack", args->slack,
                  "Room for real time: windows where something must happen grow by D, windows "
                  "where it must not shrink by D (default 100ms in real time, 0 in virtual time)")
      ->type_name("D")
      ->check([](const std::string& text) {
        return parse_duration(text) ? std::string()
                                    : "'" + text + "' is not a duration (e.g. 100ms, 0.5s)";
      });
  cmd->add_option("--set", args->sets, "Set a scenario variable: name=value (repeatable)")
      ->type_name("NAME=VALUE")
      ->allow_extra_args(false);
  cmd->add_option("-j,--jobs", args->jobs,
                  "Runs at a time: N, or auto (the default): one per core for runs in virtual "
                  "time, " +
                      std::to_string(harness::kRealTimeRunsPerCore) +
                      " per core for runs in real time (an external client)")
      ->type_name("N|auto")
      ->check([](const std::string& text) {
        return parse_jobs(text)
                   ? std::string()
                   : "expected a number of runs from 1 to 1024, or auto; got '" + text + "'";
      });
  cmd->add_option("--shard", args->shard,
                  "Run shard K of N: a share of the selected scenarios, balanced by their "
                  "expected time and stable as files are added, so N CI jobs together run each "
                  "scenario once (join their results with hil report merge)")
      ->type_name("K/N")
      ->check([](const std::string& text) {
        std::string error;
        return harness::parse_shard(text, &error) ? std::string() : error;
      });
  cmd->add_flag("--list", args->list,
                "Print the scenarios that would run, with their tags and the command line of "
                "any external client");
  cmd->add_flag("--allow-outside-paths", args->allow_outside_paths,
                "Let scenarios name files outside their root (the parent of the scenario's "
                "folder): absolute paths, ../ past it, symlinks out of it");
  cmd->add_flag("-v,--verbose", args->verbose,
                "Show each run as it finishes and the YAML files that are not scenarios");
  cmd->footer(
      "Examples:\n"
      "  hil run scenarios/                              # every scenario, a table at the end\n"
      "  hil run scenarios/ --tags smoke --junit hil.xml --report-dir hil-report\n"
      "  hil run scenarios/logi/release.yaml --seed 42   # repeat one run exactly\n"
      "  hil run scenarios/ --repeat 20 -j 4             # hunt flaky scenarios\n"
      "  hil run scenarios/ --shard 2/4 --junit hil-2.xml  # CI job 2 of 4\n"
      "Every failure prints the command that repeats it.\n"
      "A scenario that sets hil's reference client's settings is skipped (SKIP) under\n"
      "--client-exec: the program is not given those settings. Under --sketch or --elf, a\n"
      "scenario of another car, or one that needs the behavioural mock, is skipped too.\n"
      "Exit status: 0 every scenario passed or was skipped; 1 any failed (or was flaky, or\n"
      "did not load);\n"
      "2 a malformed command line, a path that does not exist, or no scenario to run.");
  cmd->callback([&run, args] { run = [args] { return run_scenarios(*args); }; });
}

}  // namespace hil::apps
