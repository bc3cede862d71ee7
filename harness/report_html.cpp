// The report folder: per run an HTML page (verdict, steps, expectations with
// evidence, the trajectory, the timeline as a filterable table), its NDJSON
// timeline and SVG trajectory, and an index page of every run. Self-contained:
// no external scripts, fonts or styles, so it opens from a CI artifact.

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

#include "harness/report.hpp"
#include "sim/svg.hpp"

namespace hil::harness {
namespace {

namespace fs = std::filesystem;

// More rows than this make a page too slow to open; the NDJSON has them all.
constexpr std::size_t kMostTimelineRows = 20000;

std::string esc(std::string_view text) {
  return xml_escape(text);
}

std::string safe_file_name(const std::string& name) {
  std::string out;
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    out += (std::isalnum(u) != 0 || c == '-' || c == '_' || c == '.') ? c : '_';
  }
  while (!out.empty() && out.front() == '.')
    out.erase(0, 1);
  return out.empty() ? "scenario" : out;
}

std::string seconds3(Duration d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", std::chrono::duration<double>(d).count());
  return buf;
}

std::string ndjson(const Timeline& timeline) {
  // Like Timeline::to_ndjson, but a frame's text that is not UTF-8 cannot
  // stop the report from being written.
  std::string out;
  for (const auto& r : timeline.records())
    out +=
        Timeline::to_json(r).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  return out;
}

void write_file(const fs::path& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (out) out << content;
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

constexpr const char* kStyle = R"(<style>
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222}
h1 .pass,td.pass{color:#1a7f37} h1 .fail,td.fail{color:#c62828}
table{border-collapse:collapse;margin:.5em 0} td,th{border:1px solid #ddd;padding:.2em .5em;
text-align:left;vertical-align:top} th{background:#f4f4f4}
pre,code,.mono{font-family:ui-monospace,monospace;font-size:.9em}
pre{background:#f7f7f7;padding:.5em;overflow-x:auto} .meta td:first-child{font-weight:bold}
tr.fail td{background:#fdecea} #timeline td{white-space:pre}
img{max-width:100%;border:1px solid #ddd}
</style>
)";

// Filters the timeline rows by text and source; samples hidden unless asked.
constexpr const char* kFilterScript = R"(<script>
function filterTimeline(){
  var q=document.getElementById('q').value.toLowerCase();
  var src=document.getElementById('src').value;
  var samples=document.getElementById('samples').checked;
  var rows=document.querySelectorAll('#timeline tbody tr');
  var shown=0;
  for(var i=0;i<rows.length;i++){
    var r=rows[i];
    var ok=(src===''||r.dataset.source===src)&&(samples||r.dataset.kind!=='sample')&&
      (q===''||r.textContent.toLowerCase().indexOf(q)>=0);
    r.style.display=ok?'':'none'; if(ok)shown++;
  }
  document.getElementById('shown').textContent=shown+' of '+rows.length+' records';
}
document.addEventListener('DOMContentLoaded',filterTimeline);
</script>
)";

std::string verdict_span(bool passed) {
  return passed ? "<span class=\"pass\">PASS</span>" : "<span class=\"fail\">FAIL</span>";
}

std::string evidence_html(const std::vector<Record>& records) {
  if (records.empty()) return {};
  std::string out = "<pre>";
  for (const auto& r : records)
    out += esc(format_record(r)) + "\n";
  return out + "</pre>";
}

std::string steps_html(const ScenarioOutcome& o) {
  if (o.steps.empty()) return "<p>No steps ran.</p>\n";
  std::string out =
      "<table><thead><tr><th>phase</th><th>line</th><th>step</th><th>started (s)</th>"
      "<th>ended (s)</th><th>result</th></tr></thead><tbody>\n";
  for (const auto& s : o.steps) {
    out += std::string("<tr") + (s.ok ? "" : " class=\"fail\"") + "><td>" +
           esc(s.phase.empty() ? "steps" : s.phase) + "</td><td>" + std::to_string(s.line) +
           "</td><td class=\"mono\">" + esc(s.text) + "</td><td>" + seconds3(s.started) +
           "</td><td>" + seconds3(s.ended) + "</td><td>" +
           (s.ok ? std::string("ok") : "failed: " + esc(s.reason)) + "</td></tr>\n";
  }
  return out + "</tbody></table>\n";
}

std::string expectations_html(const ScenarioOutcome& o) {
  if (o.expectations.empty()) return "<p>No expectations.</p>\n";
  std::string out;
  for (const auto& e : o.expectations) {
    out += std::string("<div class=\"expectation\"><h3>") + verdict_span(e.passed) + " line " +
           std::to_string(e.line) + ": " + esc(e.label) + "</h3>\n";
    if (!e.message.empty()) out += "<p>" + esc(e.message) + "</p>\n";
    if (e.window_from || e.window_to) {
      out += "<p>window: " + (e.window_from ? seconds3(*e.window_from) + " s" : "start") + " .. " +
             (e.window_to ? seconds3(*e.window_to) + " s" : "end") + "</p>\n";
    }
    out += evidence_html(e.evidence) + "</div>\n";
  }
  return out;
}

std::string timeline_html(const Timeline& timeline) {
  std::map<std::string, int> sources;
  for (const auto& r : timeline.records())
    ++sources[std::string(to_string(r.source))];
  std::string out =
      "<p><label>filter <input id=\"q\" oninput=\"filterTimeline()\" "
      "placeholder=\"text, e.g. MV:STOP\"></label> <label>source <select id=\"src\" "
      "onchange=\"filterTimeline()\"><option value=\"\">all</option>";
  for (const auto& [source, n] : sources)
    out += "<option value=\"" + esc(source) + "\">" + esc(source) + " (" + std::to_string(n) +
           ")</option>";
  out +=
      "</select></label> <label><input type=\"checkbox\" id=\"samples\" "
      "onchange=\"filterTimeline()\"> chassis samples</label> <span id=\"shown\"></span></p>\n"
      "<table id=\"timeline\"><thead><tr><th>time (s)</th><th>source</th><th>kind</th>"
      "<th>what</th></tr></thead><tbody>\n";
  std::size_t n = 0;
  for (const auto& r : timeline.records()) {
    if (++n > kMostTimelineRows) break;
    const std::string source(to_string(r.source));
    out += "<tr data-source=\"" + esc(source) + "\" data-kind=\"" + esc(r.kind) + "\"><td>" +
           seconds3(r.at) + "</td><td>" + esc(source) + "</td><td>" + esc(r.kind) + "</td><td>" +
           esc(describe_record(r)) + "</td></tr>\n";
  }
  out += "</tbody></table>\n";
  if (timeline.size() > kMostTimelineRows) {
    out += "<p>The first " + std::to_string(kMostTimelineRows) + " of " +
           std::to_string(timeline.size()) +
           " records; <a href=\"timeline.ndjson\">timeline.ndjson</a> has them all.</p>\n";
  }
  return out;
}

std::string page_head(const std::string& title) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + esc(title) +
         "</title>\n" + kStyle + "</head>\n";
}

}  // namespace

void report_folders(std::vector<ReportEntry>& entries) {
  std::set<std::string> taken;
  for (const auto& e : entries)
    if (!e.folder.empty()) taken.insert(e.folder);
  for (std::size_t i = 0; i < entries.size();) {
    std::size_t end = i + 1;
    while (end < entries.size() && entries[end].repeat > 0)
      ++end;
    const auto& first = entries[i].outcome;
    const std::string wanted =
        safe_file_name(first.name.empty() ? fs::path(first.file).stem().string() : first.name);
    // The folders of this scenario's runs for a base name.
    const auto folders = [&](const std::string& base) {
      std::vector<std::string> out;
      for (std::size_t k = i; k < end; ++k) {
        out.push_back(entries[k].repeats > 1 ? base + "-" + std::to_string(entries[k].repeat + 1)
                                             : base);
      }
      return out;
    };
    std::string base = wanted;
    for (int n = 2;; ++n) {
      bool free = true;
      for (const auto& f : folders(base))
        free = free && taken.count(f) == 0;
      if (free) break;
      base = wanted + "-" + std::to_string(n);
    }
    const auto chosen = folders(base);
    for (std::size_t k = i; k < end; ++k) {
      if (entries[k].folder.empty()) entries[k].folder = chosen[k - i];
      taken.insert(entries[k].folder);
    }
    i = end;
  }
}

std::string run_page_html(const ReportEntry& entry) {
  const auto& o = entry.outcome;
  const bool passed = o.passed();
  std::string title = (o.name.empty() ? o.file : o.name);
  if (entry.repeats > 1)
    title += " #" + std::to_string(entry.repeat + 1) + " of " + std::to_string(entry.repeats);
  std::string out = page_head(title + (passed ? " PASS" : " FAIL"));
  out += "<body>\n<p><a href=\"../index.html\">all runs</a></p>\n";
  out += "<h1>" + verdict_span(passed) + " " + esc(title) + "</h1>\n";
  out += "<table class=\"meta\">";
  out += "<tr><td>file</td><td class=\"mono\">" + esc(o.file) + "</td></tr>";
  out += "<tr><td>seed</td><td>" + std::to_string(o.seed) + "</td></tr>";
  if (!o.tags.empty()) {
    std::string tags;
    for (const auto& t : o.tags)
      tags += (tags.empty() ? "" : ", ") + t;
    out += "<tr><td>tags</td><td>" + esc(tags) + "</td></tr>";
  }
  out += "<tr><td>run time</td><td>" + format_seconds(o.run_time) +
         (o.real_time ? " real" : " simulated") + "</td></tr>";
  char wall[32];
  std::snprintf(wall, sizeof wall, "%.3f s", o.wall_seconds);
  out += "<tr><td>wall time</td><td>" + std::string(wall) + "</td></tr>";
  if (!o.repro_command.empty())
    out += "<tr><td>repeat</td><td><code>" + esc(o.repro_command) + "</code></td></tr>";
  out += "</table>\n";
  if (!o.error.empty()) out += "<h2>Error</h2>\n<pre>" + esc(o.error) + "</pre>\n";
  if (!passed) out += "<h2>Failure</h2>\n<pre>" + esc(failure_text(o)) + "</pre>\n";
  out += "<h2>Steps</h2>\n" + steps_html(o);
  out += "<h2>Expectations</h2>\n" + expectations_html(o);
  out +=
      "<h2>Trajectory</h2>\n<p><a href=\"trajectory.svg\"><img src=\"trajectory.svg\" "
      "alt=\"the arena and the path the car drove\"></a></p>\n";
  out += "<h2>Timeline</h2>\n<p><a href=\"timeline.ndjson\">timeline.ndjson</a> (" +
         std::to_string(o.timeline.size()) + " records)";
  if (!o.wire_log.empty()) {
    const std::string name = fs::path(o.wire_log).filename().string();
    out +=
        "; the wire log, every byte each way: <a href=\"" + esc(name) + "\">" + esc(name) + "</a>";
  }
  out += "</p>\n" + timeline_html(o.timeline);
  out += kFilterScript;
  out += "</body></html>\n";
  return out;
}

void write_report_dir(const std::string& dir, std::vector<ReportEntry> entries) {
  report_folders(entries);
  const fs::path root(dir);
  std::error_code ec;
  fs::create_directories(root, ec);
  if (ec) throw std::runtime_error("cannot create " + root.string() + ": " + ec.message());

  std::string index = page_head("hil run: " + summary_line(entries));
  index += "<body>\n<h1>" + esc(summary_line(entries)) + "</h1>\n";
  index +=
      "<table><thead><tr><th>result</th><th>scenario</th><th>file</th><th>seed</th>"
      "<th>run time</th><th>wall</th><th>first failure</th></tr></thead><tbody>\n";
  for (const auto& e : entries) {
    const auto& o = e.outcome;
    const fs::path folder = root / e.folder;
    fs::create_directories(folder, ec);
    if (ec) throw std::runtime_error("cannot create " + folder.string() + ": " + ec.message());
    write_file(folder / "timeline.ndjson", ndjson(o.timeline));
    sim::SvgOptions svg;
    svg.title = o.name;
    write_file(folder / "trajectory.svg", sim::render_svg(o.arena, o.trajectories, svg));
    write_file(folder / "index.html", run_page_html(e));

    const bool passed = o.passed();
    std::string name = o.name.empty() ? o.file : o.name;
    if (e.repeats > 1) name += " #" + std::to_string(e.repeat + 1);
    char wall[32];
    std::snprintf(wall, sizeof wall, "%.3f s", o.wall_seconds);
    index += std::string("<tr") + (passed ? "" : " class=\"fail\"") + "><td class=\"" +
             (passed ? "pass\">PASS" : "fail\">FAIL") + "</td><td><a href=\"" + esc(e.folder) +
             "/index.html\">" + esc(name) + "</a></td><td class=\"mono\">" + esc(o.file) +
             "</td><td>" + std::to_string(o.seed) + "</td><td>" + format_seconds(o.run_time) +
             "</td><td>" + wall + "</td><td>" + esc(o.first_failure()) + "</td></tr>\n";
  }
  index += "</tbody></table>\n</body></html>\n";
  write_file(root / "index.html", index);
}

}  // namespace hil::harness
