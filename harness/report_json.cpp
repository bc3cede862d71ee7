// DIR/results.json: every run of a report folder, for tools (hil report
// merge joins the folders of CI shards from it).

#include <stdexcept>

#include <nlohmann/json.hpp>

#include "harness/report.hpp"

namespace hil::harness {
namespace {

constexpr const char* kFormat = "hil-results";
constexpr int kVersion = 1;

const char* verdict_word(Verdict v) {
  switch (v) {
    case Verdict::pass:
      return "pass";
    case Verdict::skip:
      return "skip";
    case Verdict::fail:
    case Verdict::flaky:
      break;
  }
  return "fail";
}

std::optional<Verdict> verdict_of(const std::string& word) {
  if (word == "pass") return Verdict::pass;
  if (word == "fail") return Verdict::fail;
  if (word == "skip") return Verdict::skip;
  return std::nullopt;
}

template <class T>
T get_or(const nlohmann::json& run, const char* key, T fallback) {
  const auto it = run.find(key);
  if (it == run.end() || it->is_null()) return fallback;
  return it->get<T>();
}

RunResult parse_run(const nlohmann::json& run, std::size_t index) {
  const std::string where = "run " + std::to_string(index + 1);
  if (!run.is_object()) throw std::runtime_error(where + " is not an object");
  RunResult r;
  try {
    r.file = get_or<std::string>(run, "file", "");
    r.name = get_or<std::string>(run, "name", "");
    r.tags = get_or<std::vector<std::string>>(run, "tags", {});
    r.repeat = get_or<int>(run, "repeat", 0);
    r.repeats = get_or<int>(run, "repeats", 1);
    r.seed = get_or<std::uint64_t>(run, "seed", 0);
    r.run_time_s = get_or<double>(run, "run_time_s", 0);
    r.wall_seconds = get_or<double>(run, "wall_seconds", 0);
    r.real_time = get_or<bool>(run, "real_time", false);
    r.folder = get_or<std::string>(run, "folder", "");
    r.first_failure = get_or<std::string>(run, "first_failure", "");
    r.failure_text = get_or<std::string>(run, "failure_text", "");
    r.repro_command = get_or<std::string>(run, "repro_command", "");
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(where + ": " + e.what());
  }
  if (r.file.empty()) throw std::runtime_error(where + " has no \"file\"");
  const auto verdict = verdict_of(get_or<std::string>(run, "verdict", ""));
  if (!verdict)
    throw std::runtime_error(where + " (" + r.file + ") has no verdict pass, fail or skip");
  r.verdict = *verdict;
  return r;
}

}  // namespace

RunResult run_result(const ReportEntry& entry) {
  const auto& o = entry.outcome;
  RunResult r;
  r.file = o.file;
  r.name = o.name;
  r.tags = o.tags;
  r.repeat = entry.repeat;
  r.repeats = entry.repeats;
  r.seed = o.seed;
  r.verdict = o.was_skipped() ? Verdict::skip : o.passed() ? Verdict::pass : Verdict::fail;
  r.run_time_s = std::chrono::duration<double>(o.run_time).count();
  r.wall_seconds = o.wall_seconds;
  r.real_time = o.real_time;
  r.folder = entry.folder;
  r.first_failure = o.was_skipped() ? o.skipped : o.first_failure();
  if (r.verdict == Verdict::fail) r.failure_text = failure_text(o);
  r.repro_command = o.repro_command;
  return r;
}

std::string results_json(const std::vector<RunResult>& runs) {
  nlohmann::json out{{"format", kFormat}, {"version", kVersion}, {"runs", nlohmann::json::array()}};
  for (const auto& r : runs) {
    out["runs"].push_back({{"file", r.file},
                           {"name", r.name},
                           {"tags", r.tags},
                           {"repeat", r.repeat},
                           {"repeats", r.repeats},
                           {"seed", r.seed},
                           {"verdict", verdict_word(r.verdict)},
                           {"run_time_s", r.run_time_s},
                           {"wall_seconds", r.wall_seconds},
                           {"real_time", r.real_time},
                           {"folder", r.folder},
                           {"first_failure", r.first_failure},
                           {"failure_text", r.failure_text},
                           {"repro_command", r.repro_command}});
  }
  return out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::vector<RunResult> parse_results_json(const std::string& text) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw std::runtime_error(std::string("not JSON: ") + e.what());
  }
  if (!doc.is_object() || doc.value("format", "") != kFormat)
    throw std::runtime_error(std::string("not hil's run results (no \"format\": \"") + kFormat +
                             "\")");
  if (doc.value("version", 0) != kVersion) {
    throw std::runtime_error("results version " + doc.value("version", nlohmann::json()).dump() +
                             ", this hil reads version " + std::to_string(kVersion));
  }
  const auto runs = doc.find("runs");
  if (runs == doc.end() || !runs->is_array()) throw std::runtime_error("no \"runs\" list");
  std::vector<RunResult> out;
  for (std::size_t i = 0; i < runs->size(); ++i)
    out.push_back(parse_run((*runs)[i], i));
  return out;
}

}  // namespace hil::harness
