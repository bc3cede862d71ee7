#include "view/page.hpp"

#include <string>

#include "view/drawing.hpp"

namespace hil::view {
namespace {

// One file, no external scripts or fonts: the page must work on a desk
// with no network and behind nothing but `hil mock`.
constexpr std::string_view kPageHead = R"HTML(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>hil mock - live view</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>
  :root { --bg:#f6f6f3; --ink:#222; --dim:#777; --line:#ddd; --accent:#0a6ebd; --bad:#c0392b; }
  * { box-sizing: border-box; }
  body { margin:0; font:13px/1.35 system-ui, sans-serif; color:var(--ink); background:var(--bg); }
  header { display:flex; gap:1em; align-items:center; padding:6px 12px; background:#fff; border-bottom:1px solid var(--line); }
  header h1 { font-size:15px; margin:0; }
  header .pill { padding:1px 8px; border-radius:9px; background:#eee; }
  header .pill.ok { background:#d9f2dc; } header .pill.bad { background:#f8d7d3; }
  main { display:grid; grid-template-columns: minmax(420px, 1fr) 470px; gap:10px; padding:10px; }
  #arena-box { background:#fff; border:1px solid var(--line); position:relative; }
  canvas { width:100%; display:block; cursor:crosshair; }
  section { background:#fff; border:1px solid var(--line); padding:6px 10px; margin-bottom:10px; }
  section h2 { font-size:12px; text-transform:uppercase; letter-spacing:.05em; color:var(--dim); margin:2px 0 6px; }
  table { border-collapse:collapse; width:100%; }
  td, th { padding:1px 4px; text-align:left; vertical-align:top; }
  .kv td:first-child { color:var(--dim); width:40%; }
  .frames { font:11px/1.3 ui-monospace, monospace; max-height:190px; overflow:auto; }
  .frames td { white-space:nowrap; } .frames .text { white-space:normal; }
  .invalid { color:var(--bad); }
  .fault { color:var(--bad); font:11px/1.3 ui-monospace, monospace; }
  textarea { width:100%; height:90px; font:11px ui-monospace, monospace; }
  button { margin:2px 2px 2px 0; }
  .row { display:flex; gap:6px; align-items:center; flex-wrap:wrap; margin:3px 0; }
  #message { min-height:1.4em; } #message.bad { color:var(--bad); }
  .cols { display:grid; grid-template-columns:1fr 1fr; gap:8px; }
  #legend { position:absolute; left:8px; bottom:6px; color:var(--dim); font-size:11px; }
</style>
</head>
<body>
<header>
  <h1>hil mock &middot; live view</h1>
  <select id="car-select" title="which car"></select>
  <span id="link" class="pill">connecting...</span>
  <span id="mode" class="pill" data-testid="mode">-</span>
  <span id="client" class="pill">client: -</span>
  <span id="rate" style="color:var(--dim)"></span>
</header>
<main>
  <div>
    <div id="arena-box">
      <canvas id="arena" width="1000" height="750"></canvas>
      <div id="legend">click on the arena: <span id="click-what">place the car</span></div>
    </div>
    <div id="pose" data-x="" data-y="" data-heading="" data-frames-to-car="0" data-frames-to-client="0"
         data-faults-injected="0" data-updates="0" style="padding:4px 0;color:var(--dim)"></div>
  </div>
  <div>
    <section>
      <h2>Telemetry</h2>
      <table class="kv" id="telemetry"></table>
    </section>
    <section>
      <h2>Wire (last frames, after faults)</h2>
      <div class="cols">
        <div><b>client &rarr; car</b><div class="frames"><table id="to_car"></table></div></div>
        <div><b>car &rarr; client</b><div class="frames"><table id="to_client"></table></div></div>
      </div>
    </section>
    <section>
      <h2>Faults</h2>
      <div id="rules" style="margin-bottom:4px"></div>
      <div id="faults" class="frames"></div>
      <div class="row">
        <select id="preset">
          <option value="">presets...</option>
          <option value="drop">drop 30% of car frames</option>
          <option value="corrupt">wrong checksum every 5th car frame</option>
          <option value="delay">delay 150 ms &plusmn; 100 ms</option>
          <option value="fragment">fragment every write</option>
          <option value="disconnect">disconnect after 40 frames</option>
        </select>
      </div>
      <textarea id="profile" spellcheck="false" placeholder="fault rules, YAML or JSON (docs/faults.md)"></textarea>
      <div class="row">
        <button id="apply-faults">Apply fault rules</button>
        <button id="clear-faults">Faults off</button>
      </div>
    </section>
    <section>
      <h2>Control</h2>
      <div class="row">
        <button data-behaviour="drop-link">Drop the link</button>
        <button data-behaviour="reset-link">Reset the link</button>
        <button data-behaviour="stall-telemetry">Stall telemetry</button>
        <input id="stall-s" type="number" value="3" min="0.1" step="0.5" style="width:4em"> s
      </div>
      <div class="row">
        <button data-behaviour="reject-next">Reject next command</button>
        <input id="reject-match" placeholder="kind, e.g. MV (all)" style="width:11em">
        <button data-behaviour="fault">Car fault</button>
        <button data-behaviour="clear-fault">Clear fault</button>
      </div>
      <div class="row">
        click on the arena to:
        <label><input type="radio" name="click" value="car" checked> place the car</label>
        <label><input type="radio" name="click" value="parcel"> drop a parcel</label>
        <label><input type="radio" name="click" value="move"> move an obstacle</label>
        <label><input type="radio" name="click" value="remove"> remove an obstacle</label>
      </div>
      <div class="row">
        heading <input id="heading" type="number" value="0" step="15" style="width:5em">&deg;
        <button id="reset">Reset the arena</button>
      </div>
      <div id="message"></div>
    </section>
  </div>
</main>
<script>
)HTML";

// The page's own script, after the shared drawing script.
constexpr std::string_view kPageScript = R"HTML(</script>
<script>
"use strict";
const $ = (id) => document.getElementById(id);
const canvas = $("arena"), ctx = canvas.getContext("2d");
let profileEdited = false;
let state = null, carIndex = 0, updates = 0, lastUpdates = [], picked = null;

const PRESETS = {
  drop: "rules:\n  - kind: drop\n    direction: to_client\n    probability: 0.3\n",
  corrupt: "rules:\n  - kind: corrupt\n    direction: to_client\n    target: checksum\n    every: 5\n",
  delay: "rules:\n  - kind: delay\n    delay: 150ms\n    jitter: 100ms\n",
  fragment: "rules:\n  - kind: fragment\n    sizes: [1, 3]\n",
  disconnect: "rules:\n  - kind: disconnect\n    at_frame: 40\n",
};

function esc(s) { return String(s).replace(/[&<>"]/g, c => ({"&":"&amp;","<":"&lt;",">":"&gt;",'"':"&quot;"}[c])); }

// ---- drawing: the shared script above (view/drawing.cpp) ----
function draw(car) { hilDraw(ctx, car, picked); }

// ---- panels ----
function fmt(v, d) { return typeof v === "number" ? v.toFixed(d) : (v === null || v === undefined ? "-" : String(v)); }
function showTelemetry(car) {
  const t = car.telemetry;
  const rows = [
    ["position", fmt(car.pose.x, 3) + ", " + fmt(car.pose.y, 3) + " m"],
    ["heading", fmt(car.pose.heading_deg, 1) + "\u00b0"],
    ["speed", fmt(t.speed_mps, 3) + " m/s (fwd " + fmt(t.vx_mps, 3) + ", left " + fmt(t.vy_mps, 3) + ")"],
    ["turning", fmt(t.turn_degps, 1) + " \u00b0/s"],
    ["sonar", t.sonar_cm + " cm" + (car.sonar.echo ? "" : " (no echo)")],
    ["line sensors H4..H1", t.line + " (deviation " + car.line.deviation + ")"],
    ["RFID", (t.rfid === null ? "-" : t.rfid) + " (" + t.rfid_reads + " reads)"],
    ["battery", fmt(t.battery_v, 2) + " V"],
    ["odometer", fmt(t.odometer_m, 2) + " m"],
    ["contacts", t.contacts],
    ["frames in / out / bad", car.stats.frames_in + " / " + car.stats.frames_out + " / " + car.stats.bad_frames],
    ["rejected / ignored", car.stats.rejected + " / " + car.stats.ignored],
    ["behaviours waiting / active", car.behaviours.waiting + " / " + car.behaviours.active],
    ["profile", (car.profile || "-") + " (reply latency " + car.reply_latency_ms + " ms)"],
    ["listening", car.address || "-"],
    ["last close", car.last_close || "-"],
  ];
  $("telemetry").innerHTML = rows.map(r => "<tr><td>" + esc(r[0]) + "</td><td>" + esc(r[1]) + "</td></tr>").join("");
}
function showFrames(id, frames) {
  $(id).innerHTML = frames.slice().reverse().map(f =>
    "<tr class='" + (f.valid ? "" : "invalid") + "' title='" + esc(f.hex) + "'><td>" + (f.t_ms / 1000).toFixed(2) +
    "</td><td>" + esc(f.kind) + "</td><td class='text'>" + esc(f.text) + "</td></tr>").join("");
}
function showFaults(car) {
  $("rules").innerHTML = car.fault_rules.length
    ? "<b>rules:</b> " + car.fault_rules.map(r => esc(r.name + " (" + r.kind + ", " + r.direction + ")")).join(", ")
      + " &middot; <b>" + car.faults_injected + "</b> injected"
    : "no fault rules &middot; " + car.faults_injected + " injected";
  $("faults").innerHTML = car.faults.slice().reverse().map(f =>
    "<div class='fault'>" + (f.t_ms / 1000).toFixed(2) + " " + esc(f.direction) + " " + esc(f.kind) + " [" + esc(f.rule) + "] " + esc(f.detail) + "</div>").join("");
}

function show(s) {
  state = s; updates++;
  const now = performance.now(); lastUpdates.push(now); while (lastUpdates.length && now - lastUpdates[0] > 2000) lastUpdates.shift();
  const sel = $("car-select");
  if (sel.options.length !== s.cars.length) {
    sel.innerHTML = s.cars.map((c, i) => "<option value='" + i + "'>" + esc(c.name + " (" + c.kind + ")") + "</option>").join("");
    sel.value = String(Math.min(carIndex, s.cars.length - 1));
  }
  const car = s.cars[carIndex]; if (!car) return;
  draw(car);
  showTelemetry(car);
  showFrames("to_car", car.frames.to_car);
  showFrames("to_client", car.frames.to_client);
  showFaults(car);
  // The rules in force, unless someone is editing them.
  if (!profileEdited && document.activeElement !== $("profile")) $("profile").value = car.fault_profile || "";
  $("mode").textContent = car.mode + (car.in_fault ? " \u00b7 FAULT" : "");
  $("mode").className = "pill" + (car.in_fault ? " bad" : "");
  $("client").textContent = car.client_connected ? "client connected" : "no client";
  $("client").className = "pill" + (car.client_connected ? " ok" : "");
  $("rate").textContent = (lastUpdates.length / 2).toFixed(0) + " updates/s \u00b7 " + s.viewers + " viewer(s) \u00b7 t " + (car.sim_time_ms / 1000).toFixed(1) + " s";
  const d = $("pose").dataset;
  d.x = car.pose.x.toFixed(4); d.y = car.pose.y.toFixed(4); d.heading = car.pose.heading_deg.toFixed(2);
  d.framesToCar = car.stats.frames_in; d.framesToClient = car.stats.frames_out;
  d.faultsInjected = car.faults_injected; d.faultRules = car.fault_rules.length; d.updates = updates;
  $("pose").textContent = "pose x " + d.x + " m, y " + d.y + " m, heading " + d.heading + "\u00b0";
}

// ---- the API ----
async function api(action, body) {
  const msg = $("message");
  try {
    const r = await fetch("/api/" + action, { method: "POST", headers: { "Content-Type": "application/json" },
                                                body: JSON.stringify(Object.assign({ car: carIndex }, body)) });
    const j = await r.json();
    msg.className = r.ok ? "" : "bad";
    msg.textContent = r.ok ? action + ": done" : action + ": " + j.error;
    return r.ok ? j : null;
  } catch (e) { msg.className = "bad"; msg.textContent = action + ": " + e; return null; }
}
$("apply-faults").onclick = async () => { if (await api("faults", { profile: $("profile").value })) profileEdited = false; };
$("clear-faults").onclick = async () => { if (await api("faults", { profile: null })) profileEdited = false; };
$("profile").oninput = () => { profileEdited = true; };
$("preset").onchange = (e) => { if (PRESETS[e.target.value]) { $("profile").value = PRESETS[e.target.value]; profileEdited = true; } };
document.querySelectorAll("[data-behaviour]").forEach(b => b.onclick = () => {
  const action = b.dataset.behaviour, body = { action };
  if (action === "stall-telemetry") body.duration_ms = Math.round(parseFloat($("stall-s").value || "3") * 1000);
  if (action === "reject-next") body.match = $("reject-match").value.trim();
  api("behaviour", body);
});
$("reset").onclick = () => { picked = null; api("reset", {}); };
$("car-select").onchange = (e) => { carIndex = parseInt(e.target.value, 10) || 0; };
const clickWhat = { car: "place the car", parcel: "drop a parcel", move: "move an obstacle (click it, then where it goes)", remove: "remove an obstacle" };
document.querySelectorAll("input[name=click]").forEach(r => r.onchange = () => { picked = null; $("click-what").textContent = clickWhat[r.value]; });
function obstacleAt(car, p) {
  let best = null, bestD = 1e9;
  for (const o of car.arena.obstacles) {
    const d = Math.hypot(o.x - p.x, o.y - p.y), reach = o.shape === "circle" ? o.radius : Math.max(o.width, o.height) / 2;
    if (d <= reach + 0.05 && d < bestD) { best = o; bestD = d; }
  }
  return best;
}
canvas.addEventListener("click", (ev) => {
  if (!state) return;
  const car = state.cars[carIndex], rect = canvas.getBoundingClientRect();
  const p = hilToArena((ev.clientX - rect.left) * canvas.width / rect.width, (ev.clientY - rect.top) * canvas.height / rect.height);
  const what = document.querySelector("input[name=click]:checked").value;
  if (what === "car") api("car", { x: p.x, y: p.y, heading_deg: parseFloat($("heading").value || "0") });
  else if (what === "parcel") api("obstacle", { op: "add", shape: "box", x: p.x, y: p.y, width: 0.3, height: 0.1, name: "parcel" });
  else if (what === "remove") { const o = obstacleAt(car, p); if (o) api("obstacle", { op: "remove", index: o.index }); }
  else if (what === "move") {
    if (picked === null) { const o = obstacleAt(car, p); if (o) picked = o.index; }
    else { api("obstacle", { op: "move", index: picked, x: p.x, y: p.y }); picked = null; }
  }
});

// ---- the stream ----
function connect() {
  const es = new EventSource("/events");
  es.onopen = () => { $("link").textContent = "live"; $("link").className = "pill ok"; };
  es.onmessage = (e) => { try { show(JSON.parse(e.data)); } catch (err) { console.error(err); } };
  es.onerror = () => { $("link").textContent = "reconnecting..."; $("link").className = "pill bad"; };
}
fetch("/api/state").then(r => r.json()).then(s => { if (s.cars.length) show(s); }).catch(() => {});
connect();
</script>
</body>
</html>
)HTML";

}  // namespace

std::string_view live_view_page() {
  static const std::string page =
      std::string(kPageHead) + std::string(drawing_script()) + std::string(kPageScript);
  return page;
}

}  // namespace hil::view
