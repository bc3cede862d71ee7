// The console table, the failure blocks and the text helpers every report
// format shares.

#include "harness/report.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>

#include "base/enum_names.hpp"
#include "base/text.hpp"

namespace hil::harness {
namespace {

// Field `key` of a record's data as text ("" when absent).
std::string field(const nlohmann::json& data, const char* key) {
  if (!data.is_object()) return {};
  const auto it = data.find(key);
  if (it == data.end() || it->is_null()) return {};
  if (it->is_string()) return it->get<std::string>();
  return it->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

bool flag(const nlohmann::json& data, const char* key, bool fallback) {
  if (!data.is_object()) return fallback;
  const auto it = data.find(key);
  return it != data.end() && it->is_boolean() ? it->get<bool>() : fallback;
}

std::string fixed(double value, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

double number(const nlohmann::json& data, const char* key) {
  if (!data.is_object()) return 0;
  const auto it = data.find(key);
  return it != data.end() && it->is_number() ? it->get<double>() : 0;
}

std::string describe_wire(const Record& r) {
  const auto& d = r.data;
  if (r.kind == WireKind::frame) {
    const std::string dir = field(d, "dir");
    const std::string stage = field(d, "stage");
    std::string who;
    if (dir == "to_car") {
      who = stage == "sent" ? "client sent" : "car received";
    } else if (dir == "to_client") {
      who = stage == "sent" ? "car sent" : "client received";
    } else {
      who = "frame";
    }
    std::string bytes = field(d, "text");
    bytes = bytes.empty() ? field(d, "hex") : escape_controls(bytes);
    if (bytes.empty()) bytes = field(d, "frame");
    std::string out = who + "  " + bytes;
    if (!flag(d, "valid", true)) {
      const std::string error = field(d, "error");
      out += "  (invalid" + (error.empty() ? std::string() : ": " + error) + ")";
    }
    return out;
  }
  if (r.kind == WireKind::open) {
    std::string out = "open";
    if (d.is_object())
      for (const auto& [key, value] : d.items())
        out += " " + key + "=" + field(d, key.c_str());
    return out;
  }
  if (r.kind == WireKind::close) {
    std::string out = "close";
    if (const auto by = field(d, "by"); !by.empty()) out += " by " + by;
    if (const auto reason = field(d, "reason"); !reason.empty()) out += ": " + reason;
    return out;
  }
  return {};
}

std::string describe_client(const Record& r) {
  const auto& d = r.data;
  if (r.kind == ClientKind::connection) return "connection " + field(d, "state");
  if (r.kind == ClientKind::command) {
    std::string out = "command " + field(d, "command") + " " + field(d, "state");
    if (const auto request = field(d, "request"); !request.empty()) out += " (" + request + ")";
    return out;
  }
  if (r.kind == ClientKind::notice) return "notice: " + field(d, "text");
  if (r.kind == ClientKind::action) {
    std::string out = "action '" + field(d, "text") + "' ";
    if (flag(d, "ok", true)) return out + "ok";
    return out + "failed: " + field(d, "reason");
  }
  if (r.kind == ClientKind::output) return "output: " + escape_controls(field(d, "line"));
  if (r.kind == ClientKind::exit) return "exit code " + field(d, "code");
  if (r.kind == ClientKind::origin) return field(d, "text");
  return {};
}

std::string describe_sim(const Record& r) {
  const auto& d = r.data;
  if (r.kind == SimKind::sample) {
    return "sample x=" + fixed(number(d, "x_m"), 3) + " m y=" + fixed(number(d, "y_m"), 3) +
           " m heading=" + fixed(number(d, "heading_deg"), 1) +
           " deg speed=" + fixed(number(d, "speed_mps"), 3) + " m/s";
  }
  if (r.kind == SimKind::station) return "station " + field(d, "station");
  if (r.kind == SimKind::collision) return "collision with " + field(d, "with");
  return {};
}

std::string describe_step(const Record& r) {
  const auto& d = r.data;
  if (r.kind == StepKind::start) return "start  " + field(d, "text");
  if (r.kind == StepKind::end) {
    if (flag(d, "ok", true)) return "end    " + field(d, "text") + "  ok";
    return "end    " + field(d, "text") + "  FAILED: " + field(d, "reason");
  }
  return {};
}

}  // namespace

std::string describe_record(const Record& r) {
  std::string text;
  switch (r.source()) {
    case Source::wire:
      text = describe_wire(r);
      break;
    case Source::fault: {
      text = std::string(r.kind.name());
      if (const auto dir = field(r.data, "dir"); !dir.empty()) text += " " + dir;
      if (const auto detail = field(r.data, "detail"); !detail.empty()) text += ": " + detail;
      if (const auto rule = field(r.data, "rule"); !rule.empty()) text += " (rule " + rule + ")";
      break;
    }
    case Source::client:
      text = describe_client(r);
      break;
    case Source::sim:
      text = describe_sim(r);
      break;
    case Source::step:
      text = describe_step(r);
      break;
    case Source::car:
      if (r.kind == CarEventKind::behaviour) text = "behaviour " + field(r.data, "name");
      if (r.kind == CarEventKind::fault_state) text = "fault state " + field(r.data, "on");
      break;
  }
  if (!text.empty()) return text;
  // A kind this report does not know yet: show everything it carries.
  text = std::string(r.kind.name());
  if (r.data.is_object() && !r.data.empty())
    text += " " + r.data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return text;
}

namespace {

// Up to `columns` characters of `text` (UTF-8 aware), "..." when cut.
std::string shorten(const std::string& text, std::size_t columns) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) {
      if (++count > columns) {
        std::size_t cut = i;
        // Back off three characters for the "...".
        for (int k = 0; k < 3 && cut > 0; ++k) {
          do {
            --cut;
          } while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80);
        }
        return text.substr(0, cut) + "...";
      }
    }
  }
  return text;
}

std::size_t columns_of(const std::string& text) {
  std::size_t n = 0;
  for (const char c : text)
    if ((static_cast<unsigned char>(c) & 0xC0) != 0x80) ++n;
  return n;
}

std::string pad(const std::string& text, std::size_t columns) {
  const std::size_t have = columns_of(text);
  return have >= columns ? text : text + std::string(columns - have, ' ');
}

// The first line only: a message that spans lines would break the table.
std::string first_line(const std::string& text) {
  const auto nl = text.find('\n');
  return nl == std::string::npos ? text : text.substr(0, nl);
}

std::string display_name(const ReportEntry& e) {
  std::string name = e.outcome.name.empty() ? e.outcome.file : e.outcome.name;
  if (e.repeats > 1) name += " #" + std::to_string(e.repeat + 1);
  return name;
}

constexpr const char* kRed = "\033[31m";
constexpr const char* kGreen = "\033[32m";
constexpr const char* kYellow = "\033[33m";
constexpr const char* kCyan = "\033[36m";
constexpr const char* kBold = "\033[1m";
constexpr const char* kReset = "\033[0m";

std::string paint(const std::string& text, const char* colour, bool on) {
  return on ? std::string(colour) + text + kReset : text;
}

const char* colour_of(Verdict v) {
  switch (v) {
    case Verdict::pass:
      return kGreen;
    case Verdict::fail:
      return kRed;
    case Verdict::flaky:
      return kYellow;
    case Verdict::skip:
      return kCyan;
  }
  return kReset;
}

// The records a person needs to see why a step failed: what happened just
// before it ended (frames, client events, steps), not the chassis samples.
std::vector<Record> evidence_for_step(const StepOutcome& step, const Timeline& timeline) {
  constexpr std::size_t before = 10;
  constexpr std::size_t after = 3;
  const Time until = step.ended + std::chrono::milliseconds(300);
  std::vector<Record> earlier;
  std::vector<Record> later;
  for (const auto& r : timeline.records()) {
    if (r.kind == SimKind::sample) continue;
    if (r.at <= step.ended) {
      earlier.push_back(r);
    } else if (r.at <= until && later.size() < after) {
      later.push_back(r);
    }
  }
  if (earlier.size() > before) earlier.erase(earlier.begin(), earlier.end() - before);
  earlier.insert(earlier.end(), later.begin(), later.end());
  return earlier;
}

void append_evidence(std::string& out, const std::vector<Record>& records) {
  constexpr std::size_t most = 16;
  if (records.empty()) return;
  out += "    evidence:\n";
  const std::size_t shown = std::min(records.size(), most);
  for (std::size_t i = 0; i < shown; ++i)
    out += "    " + format_record(records[i]) + "\n";
  if (records.size() > shown)
    out += "      ... " + std::to_string(records.size() - shown) + " more\n";
}

}  // namespace

constexpr auto kVerdictNames =
    base::enum_names<Verdict>({Verdict::pass, "PASS"}, {Verdict::fail, "FAIL"},
                              {Verdict::flaky, "FLAKY"}, {Verdict::skip, "SKIP"});

const char* to_string(Verdict verdict) {
  return kVerdictNames.name(verdict).data();  // every name is a literal, so it ends in a NUL
}

std::vector<ScenarioSummary> summarize(const std::vector<ReportEntry>& entries) {
  std::vector<ScenarioSummary> out;
  for (const auto& e : entries) {
    // A scenario's runs are consecutive; each group starts at its first run.
    const bool same = !out.empty() && e.repeat > 0;
    if (!same) out.push_back(ScenarioSummary{e.outcome.file, e.outcome.name, Verdict::pass, 0, 0});
    auto& s = out.back();
    ++s.runs;
    if (!e.outcome.passed()) ++s.failed_runs;
    // A scenario is skipped for what it asks of the client, so each of its
    // runs is.
    if (e.outcome.was_skipped()) {
      s.verdict = Verdict::skip;
      continue;
    }
    s.verdict = s.failed_runs == 0        ? Verdict::pass
                : s.failed_runs == s.runs ? Verdict::fail
                                          : Verdict::flaky;
  }
  return out;
}

std::string summary_line(const std::vector<ReportEntry>& entries) {
  std::size_t passed = 0;
  std::size_t failed = 0;
  std::size_t skipped = 0;
  for (const auto& s : summarize(entries))
    (s.verdict == Verdict::pass ? passed : s.verdict == Verdict::skip ? skipped : failed) += 1;
  std::string line = std::to_string(passed) + " passed, " + std::to_string(failed) + " failed";
  if (skipped > 0) line += ", " + std::to_string(skipped) + " skipped";
  return line;
}

bool want_color(int fd) {
  const char* no_color = std::getenv("NO_COLOR");
  if (no_color != nullptr && *no_color != '\0') return false;
  return ::isatty(fd) == 1;
}

std::size_t terminal_width(int fd, std::size_t fallback) {
  winsize w{};
  if (::isatty(fd) != 1 || ::ioctl(fd, TIOCGWINSZ, &w) != 0 || w.ws_col == 0) return fallback;
  return w.ws_col;
}

std::string format_seconds(Duration d) {
  return fixed(std::chrono::duration<double>(d).count(), 3) + " s";
}

std::string format_record(const Record& record) {
  char time[32];
  std::snprintf(time, sizeof time, "%9.3f s", std::chrono::duration<double>(record.at).count());
  return std::string(time) + "  " + pad(std::string(to_string(record.source())), 6) + "  " +
         describe_record(record);
}

std::string failure_text(const ScenarioOutcome& o) {
  std::string out = "FAIL " + (o.name.empty() ? o.file : o.name);
  std::string where = o.file;
  if (o.error.empty() || o.seed != 0) {
    where += (where.empty() ? "" : ", ") + std::string("seed ") + std::to_string(o.seed);
  }
  if (!where.empty()) out += "  (" + where + ")";
  out += "\n";
  if (!o.error.empty()) {
    out += "  error: " + o.error + "\n";
  }
  bool first_step = true;
  std::size_t not_run = 0;
  for (const auto& s : o.steps) {
    if (s.ok) continue;
    if (!s.ran) {
      ++not_run;
      continue;
    }
    if (!first_step) {
      // Teardown after the failure, say: one line each, the first has the evidence.
      out += "  " + (s.phase.empty() || s.phase == "steps" ? std::string() : s.phase + " ") +
             "step line " + std::to_string(s.line) + " (" + s.text + ") failed at " +
             format_seconds(s.ended) + ": " + s.reason + "\n";
      continue;
    }
    first_step = false;
    out += "  " + (s.phase.empty() || s.phase == "steps" ? std::string() : s.phase + " ") +
           "step line " + std::to_string(s.line) + " (" + s.text + ") failed at " +
           format_seconds(s.ended) + ": " + s.reason + "\n";
    append_evidence(out, evidence_for_step(s, o.timeline));
  }
  if (not_run > 0) out += "  (" + std::to_string(not_run) + " later step(s) did not run)\n";
  for (const auto& e : o.expectations) {
    if (e.passed) continue;
    out += "  " + e.where();
    if (!e.label.empty()) out += " (" + e.label + ")";
    out += ": " + e.message + "\n";
    if (e.window_from || e.window_to) {
      out += "    window: " + (e.window_from ? format_seconds(*e.window_from) : "start") + " .. " +
             (e.window_to ? format_seconds(*e.window_to) : "end") + "\n";
    }
    if (!e.evidence.empty() || !e.window_from) {
      append_evidence(out, e.evidence);
    } else {
      // The checker found nothing to show: what happened in the window, then.
      const Time to = e.window_to.value_or(Time::max());
      std::vector<Record> seen;
      for (const auto& r : o.timeline.records())
        if (r.at >= *e.window_from && r.at <= to && !(r.kind == SimKind::sample)) seen.push_back(r);
      append_evidence(out, seen);
    }
  }
  if (!o.repro_command.empty()) out += "  repeat: " + o.repro_command + "\n";
  return out;
}

void write_console(std::ostream& out, const std::vector<ReportEntry>& entries,
                   const ConsoleOptions& options) {
  const bool c = options.color;
  std::size_t name_width = 8;
  for (const auto& e : entries)
    name_width = std::max(name_width, std::min<std::size_t>(columns_of(display_name(e)), 48));
  const std::vector<ScenarioSummary> summaries = summarize(entries);

  struct Row {
    std::string name, result, time, wall, message;
    const char* colour;
  };
  // The verdict of each entry's scenario: a failed run of a flaky scenario
  // reads FLAKY, so the table shows it where the failure is.
  std::vector<Verdict> scenario_verdict;
  {
    std::size_t group = 0;
    for (std::size_t i = 0; i < entries.size(); ++i) {
      if (i > 0 && entries[i].repeat == 0) ++group;
      scenario_verdict.push_back(group < summaries.size() ? summaries[group].verdict
                                                          : Verdict::fail);
    }
  }
  std::vector<Row> rows;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& e = entries[i];
    const auto& o = e.outcome;
    const bool ok = o.passed();
    const Verdict v =
        o.was_skipped() ? Verdict::skip
        : ok            ? Verdict::pass
                        : (scenario_verdict[i] == Verdict::flaky ? Verdict::flaky : Verdict::fail);
    Row row{shorten(display_name(e), name_width),
            to_string(v),
            "-",
            fixed(o.wall_seconds, 3) + " s",
            shorten(first_line(o.was_skipped() ? o.skipped : o.first_failure()), 400),
            colour_of(v)};
    if (!o.was_skipped() && (o.error.empty() || o.run_time.count() > 0))
      row.time = format_seconds(o.run_time) + (o.real_time ? " real" : " sim");
    rows.push_back(std::move(row));
  }
  std::size_t time_width = 4;
  std::size_t wall_width = 4;
  for (const auto& r : rows) {
    time_width = std::max(time_width, columns_of(r.time));
    wall_width = std::max(wall_width, columns_of(r.wall));
  }
  const std::size_t used = name_width + 2 + 6 + 2 + time_width + 2 + wall_width + 2;
  const std::size_t message_width = options.width > used + 20 ? options.width - used : 20;

  out << paint(pad("SCENARIO", name_width) + "  " + pad("RESULT", 6) + "  " +
                   pad("TIME", time_width) + "  " + pad("WALL", wall_width) + "  FIRST FAILURE",
               kBold, c)
      << '\n';
  for (const auto& r : rows) {
    std::string line = pad(r.name, name_width) + "  " + paint(pad(r.result, 6), r.colour, c) +
                       "  " + pad(r.time, time_width) + "  " + pad(r.wall, wall_width);
    if (!r.message.empty()) line += "  " + shorten(r.message, message_width);
    while (!line.empty() && line.back() == ' ')
      line.pop_back();
    out << line << '\n';
  }

  for (const auto& e : entries) {
    if (e.outcome.passed()) continue;
    std::string block = failure_text(e.outcome);
    out << '\n';
    if (e.repeats > 1) out << "run " << e.repeat + 1 << " of " << e.repeats << ":\n";
    if (c) {
      // Colour only the verdict word of the block's first line.
      out << paint("FAIL", kRed, true) << block.substr(4);
    } else {
      out << block;
    }
  }

  bool any_flaky = false;
  for (const auto& s : summaries) {
    if (s.verdict != Verdict::flaky) continue;
    if (!any_flaky) out << '\n';
    any_flaky = true;
    out << paint("FLAKY", colour_of(Verdict::flaky), c) << ' ' << s.name << " (" << s.file
        << "): " << s.failed_runs << " of " << s.runs << " runs failed\n";
  }
  // Why each skipped scenario was not run, once (its repeats are alike).
  bool any_skipped = false;
  for (const auto& e : entries) {
    if (!e.outcome.was_skipped() || e.repeat > 0) continue;
    if (!any_skipped) out << '\n';
    any_skipped = true;
    out << paint("SKIP", colour_of(Verdict::skip), c) << ' ' << e.outcome.name << " ("
        << e.outcome.file << "): " << e.outcome.skipped << '\n';
  }
  out << '\n' << summary_line(entries) << '\n';
}

}  // namespace hil::harness
