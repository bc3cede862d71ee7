// The report folder: per run an HTML page (verdict, steps, expectations with
// evidence, a playback of the run on a time slider drawn by the live view's
// own script, the trajectory, the timeline as a filterable table), its NDJSON
// timeline and SVG trajectory, and an index page of every run. Self-contained:
// no external scripts, fonts or styles, so it opens from a CI artifact.

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

#include "base/text.hpp"
#include "harness/atomic_file.hpp"
#include "harness/report.hpp"
#include "sim/geometry.hpp"
#include "sim/svg.hpp"
#include "view/drawing.hpp"

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

// Whole files only: a CI job that uploads the folder while a later run is
// still being written, or a crash, never leaves a half page behind.
void write_file(const fs::path& path, const std::string& content) {
  write_file_atomically(path.string(), content);
}

constexpr const char* kStyle = R"(<style>
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222}
h1 .pass,td.pass{color:#1a7f37} h1 .fail,td.fail{color:#c62828} h1 .skip,td.skip{color:#00838f}
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
    out += std::string("<div class=\"expectation\"><h3>") + verdict_span(e.passed) + " " +
           esc(e.where()) + ": " + esc(e.label) + "</h3>\n";
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
    ++sources[std::string(to_string(r.source()))];
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
    const std::string source(to_string(r.source()));
    out += "<tr data-source=\"" + esc(source) + "\" data-kind=\"" +
           esc(std::string(r.kind.name())) + "\"><td>" + seconds3(r.at) + "</td><td>" +
           esc(source) + "</td><td>" + esc(std::string(r.kind.name())) + "</td><td>" +
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

// What the playback carries at most: enough for minutes of run at full
// detail; longer runs are thinned evenly (the NDJSON keeps everything).
constexpr std::size_t kMostPlaybackSamples = 12000;  // per car
constexpr std::size_t kMostPlaybackRecords = 20000;  // frames, faults, events each

double ms_of(Duration d) {
  return std::round(std::chrono::duration<double, std::milli>(d).count() * 10) / 10;
}

// The recorded run as the playback script reads it: the arena in the live
// view's shape, each car's poses over time, and what crossed the wire.
nlohmann::json playback_json(const ScenarioOutcome& o) {
  using nlohmann::json;
  json j;
  j["arena"] = view::arena_json(o.arena);
  j["run_ms"] = ms_of(o.run_time);
  j["cars"] = json::array();
  for (const auto& t : o.trajectories) {
    json samples = json::array();
    const std::size_t n = t.samples.size();
    const std::size_t stride =
        n > kMostPlaybackSamples ? (n + kMostPlaybackSamples - 1) / kMostPlaybackSamples : 1;
    for (std::size_t i = 0; i < n; i += stride) {
      const auto& s = t.samples[i];
      samples.push_back({ms_of(s.time), sim::round_to(s.pose.x_m, 1e-4),
                         sim::round_to(s.pose.y_m, 1e-4),
                         sim::round_to(sim::rad_to_deg(s.pose.heading_rad), 0.01)});
    }
    if (n > 0 && (n - 1) % stride != 0) {
      const auto& s = t.samples.back();
      samples.push_back({ms_of(s.time), sim::round_to(s.pose.x_m, 1e-4),
                         sim::round_to(s.pose.y_m, 1e-4),
                         sim::round_to(sim::rad_to_deg(s.pose.heading_rad), 0.01)});
    }
    json marks = json::array();
    for (const auto& m : t.marks) {
      const char* kind = m.kind == sim::MarkKind::collision ? "collision"
                         : m.kind == sim::MarkKind::stop    ? "stop"
                         : m.kind == sim::MarkKind::station ? "station"
                                                            : "note";
      marks.push_back({ms_of(m.time), sim::round_to(m.position_m.x_m, 1e-4),
                       sim::round_to(m.position_m.y_m, 1e-4), kind, m.label});
    }
    j["cars"].push_back({{"name", t.vehicle},
                         {"footprint", {{"length", t.length_m}, {"width", t.width_m}}},
                         {"samples", samples},
                         {"marks", marks}});
  }
  json frames = json::array(), faults = json::array(), events = json::array(),
       fault_state = json::array();
  for (const auto& r : o.timeline.records()) {
    const double at = ms_of(r.at);
    if (r.kind == WireKind::frame) {
      if (r.data.value("stage", "") != "delivered" || frames.size() >= kMostPlaybackRecords)
        continue;
      const std::string text =
          r.data.contains("text") ? r.data.value("text", "") : r.data.value("hex", "");
      frames.push_back({at, r.data.value("dir", ""), r.data.value("frame", ""), text,
                        r.data.value("valid", true)});
    } else if (r.source() == Source::fault) {
      if (faults.size() < kMostPlaybackRecords)
        faults.push_back({at, r.data.value("dir", ""), std::string(r.kind.name()),
                          r.data.value("rule", ""), r.data.value("detail", "")});
    } else if (r.kind == CarEventKind::fault_state) {
      fault_state.push_back({at, r.data.value("on", false)});
    } else if ((r.kind == StepKind::start) || r.source() == Source::client ||
               ((r.source() == Source::sim && r.kind != SimKind::sample))) {
      if (events.size() < kMostPlaybackRecords)
        events.push_back({at, std::string(to_string(r.source())), std::string(r.kind.name()),
                          describe_record(r)});
    }
  }
  j["frames"] = std::move(frames);
  j["faults"] = std::move(faults);
  j["events"] = std::move(events);
  j["fault_state"] = std::move(fault_state);
  return j;
}

// JSON inside a <script> element: no '<' may reach the HTML parser, and a
// JSON string may spell it \u003c.
std::string script_json(const nlohmann::json& j) {
  const std::string text = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  return out;
}

constexpr const char* kPlaybackStyle = R"(<style>
#playback{display:grid;grid-template-columns:minmax(420px,1fr) 440px;gap:10px;align-items:start}
#pb-canvas{width:100%;border:1px solid #ddd;background:#fff}
#pb-controls{display:flex;gap:.5em;align-items:center;margin:.3em 0}
#pb-slider{flex:1} #playback>div{min-width:0} #playback>div:last-child{overflow-x:auto}
#playback .frames{font-family:ui-monospace,monospace;font-size:11px}
#playback .frames td{border:none;padding:0 .4em 0 0;white-space:nowrap}
#playback .invalid{color:#c62828} #playback h3{font-size:13px;margin:.6em 0 .2em}
</style>
)";

// Plays the run back with the live view's drawing (hilFit, hilDrawArena,
// hilDrawCar). The time can be set from the address: index.html#t=12.5.
constexpr const char* kPlaybackScript = R"JS(<script>
"use strict";
(function () {
  const data = JSON.parse(document.getElementById("pb-data").textContent);
  const $ = (id) => document.getElementById(id);
  const canvas = $("pb-canvas"), ctx = canvas.getContext("2d"), slider = $("pb-slider");
  const esc = (s) => String(s).replace(/[&<>"]/g, c => ({"&":"&amp;","<":"&lt;",">":"&gt;",'"':"&quot;"}[c]));
  // The index of the last row at or before t (rows sorted by row[0]).
  function upTo(rows, t) {
    let lo = 0, hi = rows.length;
    while (lo < hi) { const mid = (lo + hi) >> 1; if (rows[mid][0] <= t) lo = mid + 1; else hi = mid; }
    return lo - 1;
  }
  function poseAt(samples, t) {
    const i = upTo(samples, t);
    if (i < 0) { const s = samples[0]; return { x: s[1], y: s[2], heading_deg: s[3] }; }
    const a = samples[i], b = samples[Math.min(i + 1, samples.length - 1)];
    const f = b[0] > a[0] ? Math.min(1, (t - a[0]) / (b[0] - a[0])) : 0;
    let dh = b[3] - a[3]; dh -= 360 * Math.round(dh / 360);
    return { x: a[1] + f * (b[1] - a[1]), y: a[2] + f * (b[2] - a[2]), heading_deg: a[3] + f * dh };
  }
  function last(rows, t, n, keep) {
    const out = [];
    for (let i = upTo(rows, t); i >= 0 && out.length < n; --i) if (!keep || keep(rows[i])) out.push(rows[i]);
    return out;
  }
  function show(t) {
    t = Math.max(0, Math.min(data.run_ms, t));
    hilFit(canvas, data.arena);
    hilDrawArena(ctx, data.arena, null);
    const fs = upTo(data.fault_state, t), inFault = fs >= 0 && data.fault_state[fs][1];
    const poses = [];
    data.cars.forEach((car, n) => {
      if (!car.samples.length) return;
      const k = upTo(car.samples, t), trail = car.samples.slice(0, k + 1).map(s => [s[1], s[2]]);
      const pose = poseAt(car.samples, t);
      trail.push([pose.x, pose.y]);
      hilDrawCar(ctx, { pose, footprint: car.footprint, trail, in_fault: inFault,
                        label: data.cars.length > 1 ? car.name : "" });
      for (const m of car.marks) {
        if (m[0] > t) continue;
        ctx.fillStyle = m[3] === "collision" ? "#c62828" : m[3] === "station" ? "#a60" : "#555";
        ctx.beginPath(); ctx.arc(hilPx(m[1]), hilPy(m[2]), 3, 0, 2 * Math.PI); ctx.fill();
      }
      poses.push(pose);
    });
    const d = $("pb-pose").dataset;
    d.tMs = t.toFixed(1);
    if (poses.length) { d.x = poses[0].x.toFixed(4); d.y = poses[0].y.toFixed(4); d.heading = poses[0].heading_deg.toFixed(2); }
    d.framesToCar = upTo(data.frames, t) < 0 ? 0 : data.frames.slice(0, upTo(data.frames, t) + 1).filter(f => f[1] === "to_car").length;
    d.faults = upTo(data.faults, t) + 1;
    $("pb-time").textContent = (t / 1000).toFixed(2) + " / " + (data.run_ms / 1000).toFixed(2) + " s";
    $("pb-pose").textContent = poses.length
      ? "x " + d.x + " m, y " + d.y + " m, heading " + d.heading + "\u00b0" + (inFault ? " \u00b7 FAULT" : "") : "no chassis recorded";
    const frameRows = (dir) => last(data.frames, t, 8, f => f[1] === dir).map(f =>
      "<tr class='" + (f[4] ? "" : "invalid") + "'><td>" + (f[0] / 1000).toFixed(2) + "</td><td>" + esc(f[2]) +
      "</td><td>" + esc(f[3]) + "</td></tr>").join("");
    $("pb-to-car").innerHTML = frameRows("to_car");
    $("pb-to-client").innerHTML = frameRows("to_client");
    $("pb-faults").innerHTML = last(data.faults, t, 6).map(f => "<tr><td>" + (f[0] / 1000).toFixed(2) + "</td><td>" +
      esc(f[1] + " " + f[2] + " [" + f[3] + "] " + f[4]) + "</td></tr>").join("") || "<tr><td>none yet</td></tr>";
    $("pb-events").innerHTML = last(data.events, t, 8).map(e => "<tr><td>" + (e[0] / 1000).toFixed(2) + "</td><td>" +
      esc(e[1]) + "</td><td>" + esc(e[3]) + "</td></tr>").join("");
  }
  let playing = false, lastTick = 0;
  function tick(now) {
    if (!playing) return;
    const speed = parseFloat($("pb-speed").value) || 1;
    const t = parseFloat(slider.value) + (lastTick ? (now - lastTick) * speed : 0);
    lastTick = now;
    slider.value = Math.min(data.run_ms, t);
    show(parseFloat(slider.value));
    if (t >= data.run_ms) { playing = false; $("pb-play").textContent = "play"; return; }
    requestAnimationFrame(tick);
  }
  $("pb-play").onclick = () => {
    playing = !playing; $("pb-play").textContent = playing ? "pause" : "play"; lastTick = 0;
    if (playing) { if (parseFloat(slider.value) >= data.run_ms) slider.value = 0; requestAnimationFrame(tick); }
  };
  slider.max = data.run_ms;
  slider.oninput = () => show(parseFloat(slider.value));
  function fromAddress() {
    const m = /t=([0-9.]+)/.exec(location.hash);
    slider.value = m ? parseFloat(m[1]) * 1000 : data.run_ms;
    show(parseFloat(slider.value));
  }
  window.addEventListener("hashchange", fromAddress);
  fromAddress();
})();
</script>
)JS";

std::string playback_html(const ScenarioOutcome& o) {
  std::string out = kPlaybackStyle;
  out +=
      "<p>The run replayed with the live view's drawing: drag the slider or press play "
      "(the address can pick a time: <code>#t=2.5</code>).</p>\n"
      "<div id=\"playback\"><div>\n"
      "<canvas id=\"pb-canvas\" width=\"1000\" height=\"750\"></canvas>\n"
      "<div id=\"pb-controls\"><button id=\"pb-play\">play</button>"
      "<input type=\"range\" id=\"pb-slider\" min=\"0\" step=\"10\" value=\"0\">"
      "<span id=\"pb-time\"></span><select id=\"pb-speed\" title=\"playback speed\">"
      "<option value=\"0.25\">0.25x</option><option value=\"1\" selected>1x</option>"
      "<option value=\"4\">4x</option><option value=\"16\">16x</option></select></div>\n"
      "<div id=\"pb-pose\" class=\"mono\"></div></div>\n"
      "<div><h3>client to car (last 8)</h3><table class=\"frames\" id=\"pb-to-car\"></table>\n"
      "<h3>car to client (last 8)</h3><table class=\"frames\" id=\"pb-to-client\"></table>\n"
      "<h3>faults injected</h3><table class=\"frames\" id=\"pb-faults\"></table>\n"
      "<h3>steps, client, chassis</h3><table class=\"frames\" id=\"pb-events\"></table></div>\n"
      "</div>\n<script>\n";
  out += view::drawing_script();
  out += "</script>\n<script id=\"pb-data\" type=\"application/json\">" +
         script_json(playback_json(o)) + "</script>\n";
  out += kPlaybackScript;
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
  const bool skipped = o.was_skipped();
  std::string out = page_head(title + (skipped ? " SKIP" : passed ? " PASS" : " FAIL"));
  out += "<body>\n<p><a href=\"../index.html\">all runs</a></p>\n";
  out += "<h1>" +
         (skipped ? std::string("<span class=\"skip\">SKIP</span>") : verdict_span(passed)) + " " +
         esc(title) + "</h1>\n";
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
  if (skipped) out += "<h2>Not run</h2>\n<p>" + esc(o.skipped) + "</p>\n";
  if (!o.error.empty()) out += "<h2>Error</h2>\n<pre>" + esc(o.error) + "</pre>\n";
  if (!passed) out += "<h2>Failure</h2>\n<pre>" + esc(failure_text(o)) + "</pre>\n";
  out += "<h2>Playback</h2>\n" + playback_html(o);
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

std::string index_html(const std::vector<RunResult>& runs, const std::string& heading) {
  std::string index = page_head("hil run: " + heading);
  index += "<body>\n<h1>" + esc(heading) + "</h1>\n";
  index +=
      "<table><thead><tr><th>result</th><th>scenario</th><th>file</th><th>seed</th>"
      "<th>run time</th><th>wall</th><th>first failure</th></tr></thead><tbody>\n";
  for (const auto& r : runs) {
    const bool passed = r.verdict != Verdict::fail;
    std::string name = r.name.empty() ? r.file : r.name;
    if (r.repeats > 1) name += " #" + std::to_string(r.repeat + 1);
    const std::string link =
        r.folder.empty() ? esc(name)
                         : "<a href=\"" + esc(r.folder) + "/index.html\">" + esc(name) + "</a>";
    char wall[32];
    std::snprintf(wall, sizeof wall, "%.3f s", r.wall_seconds);
    const char* result = r.verdict == Verdict::skip ? "skip\">SKIP"
                         : passed                   ? "pass\">PASS"
                                                    : "fail\">FAIL";
    index += std::string("<tr") + (passed ? "" : " class=\"fail\"") + "><td class=\"" + result +
             "</td><td>" + link + "</td><td class=\"mono\">" + esc(r.file) + "</td><td>" +
             std::to_string(r.seed) + "</td><td>" +
             format_seconds(std::chrono::duration_cast<Duration>(
                 std::chrono::duration<double>(r.run_time_s))) +
             "</td><td>" + wall + "</td><td>" + esc(r.first_failure) + "</td></tr>\n";
  }
  index += "</tbody></table>\n</body></html>\n";
  return index;
}

void write_report_dir(const std::string& dir, std::vector<ReportEntry> entries) {
  report_folders(entries);
  const fs::path root(dir);
  std::error_code ec;
  fs::create_directories(root, ec);
  if (ec) throw std::runtime_error("cannot create " + root.string() + ": " + ec.message());

  std::vector<RunResult> runs;
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
    runs.push_back(run_result(e));
  }
  write_file(root / "results.json", results_json(runs));
  write_file(root / "index.html", index_html(runs, summary_line(entries)));
}

}  // namespace hil::harness
