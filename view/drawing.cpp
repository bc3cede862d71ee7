#include "view/drawing.hpp"

#include <cmath>
#include <utility>
#include <variant>

#include "sim/geometry.hpp"

namespace hil::view {
namespace {

using nlohmann::json;

json obstacle_json(const sim::Obstacle& o, std::size_t index) {
  json j;
  j["index"] = index;
  if (const auto* box = std::get_if<sim::BoxObstacle>(&o)) {
    j["shape"] = "box";
    j["name"] = box->name;
    j["x"] = box->center_m.x_m;
    j["y"] = box->center_m.y_m;
    j["width"] = box->width_m;
    j["height"] = box->height_m;
    j["angle_deg"] = sim::rad_to_deg(box->angle_rad);
  } else {
    const auto& disc = std::get<sim::CircleObstacle>(o);
    j["shape"] = "circle";
    j["name"] = disc.name;
    j["x"] = disc.center_m.x_m;
    j["y"] = disc.center_m.y_m;
    j["radius"] = disc.radius_m;
  }
  return j;
}

// Plain functions on the page's globals, no modules: the same text runs in
// the live page and in a report opened from a CI artifact (file://).
constexpr std::string_view kScript = R"JS(
"use strict";
let hilView = { scale: 200, ox: 20, oy: 20, h: 3 };
function hilFit(canvas, arena) {
  const margin = 20;
  const sx = (canvas.width - 2 * margin) / arena.width, sy = (canvas.height - 2 * margin) / arena.height;
  hilView = { scale: Math.min(sx, sy), ox: margin, oy: margin, h: arena.height };
}
function hilPx(x) { return hilView.ox + x * hilView.scale; }
function hilPy(y) { return hilView.oy + (hilView.h - y) * hilView.scale; }
function hilToArena(cx, cy) {
  return { x: (cx - hilView.ox) / hilView.scale, y: hilView.h - (cy - hilView.oy) / hilView.scale };
}
function hilDrawObstacle(ctx, o, fill) {
  const px = hilPx, py = hilPy, k = hilView.scale;
  ctx.fillStyle = fill; ctx.strokeStyle = "#555"; ctx.lineWidth = 1;
  if (o.shape === "circle") {
    ctx.beginPath(); ctx.arc(px(o.x), py(o.y), o.radius * k, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
  } else {
    ctx.save(); ctx.translate(px(o.x), py(o.y)); ctx.rotate(-o.angle_deg * Math.PI / 180);
    const w = o.width * k, h = o.height * k;
    ctx.fillRect(-w / 2, -h / 2, w, h); ctx.strokeRect(-w / 2, -h / 2, w, h); ctx.restore();
  }
  ctx.fillStyle = "#333"; ctx.font = "11px sans-serif"; ctx.textAlign = "center";
  ctx.fillText(o.name + " #" + o.index, px(o.x), py(o.y) + 4);
}
function hilDrawArena(ctx, a, picked) {
  const px = hilPx, py = hilPy, k = hilView.scale, canvas = ctx.canvas;
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  ctx.fillStyle = "#fbfbf8"; ctx.fillRect(px(0), py(a.height), a.width * k, a.height * k);
  ctx.strokeStyle = "#eee"; ctx.lineWidth = 1;  // a grid every half metre
  for (let x = 0; x <= a.width + 1e-9; x += 0.5) { ctx.beginPath(); ctx.moveTo(px(x), py(0)); ctx.lineTo(px(x), py(a.height)); ctx.stroke(); }
  for (let y = 0; y <= a.height + 1e-9; y += 0.5) { ctx.beginPath(); ctx.moveTo(px(0), py(y)); ctx.lineTo(px(a.width), py(y)); ctx.stroke(); }
  if (a.walls) {
    ctx.strokeStyle = "#444"; ctx.lineWidth = Math.max(3, a.wall_thickness * k);
    ctx.strokeRect(px(0) - ctx.lineWidth / 2, py(a.height) - ctx.lineWidth / 2,
                   a.width * k + ctx.lineWidth, a.height * k + ctx.lineWidth);
  }
  for (const t of a.tapes) {
    ctx.strokeStyle = "#222"; ctx.lineWidth = Math.max(2, t.width * k); ctx.lineJoin = "round";
    ctx.beginPath(); t.points.forEach((p, i) => i ? ctx.lineTo(px(p[0]), py(p[1])) : ctx.moveTo(px(p[0]), py(p[1])));
    if (t.closed) ctx.closePath(); ctx.stroke();
  }
  for (const s of a.stations) {
    ctx.fillStyle = "rgba(230,160,20,.35)"; ctx.strokeStyle = "#c80";
    ctx.beginPath(); ctx.arc(px(s.x), py(s.y), Math.max(5, s.radius * k), 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
    ctx.fillStyle = "#a60"; ctx.font = "bold 12px sans-serif"; ctx.textAlign = "left";
    ctx.fillText("station " + s.id, px(s.x) + 10, py(s.y) - 10);
  }
  for (const o of a.obstacles) hilDrawObstacle(ctx, o, picked === o.index ? "#f5d76e" : "#c9c4b8");
}
function hilDrawCar(ctx, car) {
  const px = hilPx, py = hilPy, k = hilView.scale;
  const trail = car.trail || [];
  if (trail.length > 1) {
    ctx.strokeStyle = "rgba(10,110,189,.55)"; ctx.lineWidth = 2;
    ctx.beginPath(); trail.forEach((p, i) => i ? ctx.lineTo(px(p[0]), py(p[1])) : ctx.moveTo(px(p[0]), py(p[1]))); ctx.stroke();
  }
  const s = car.sonar;
  if (s) {
    ctx.strokeStyle = "rgba(0,160,80,.35)"; ctx.lineWidth = 1;
    for (const r of s.rays) { ctx.beginPath(); ctx.moveTo(px(s.x), py(s.y)); ctx.lineTo(px(r.x), py(r.y)); ctx.stroke(); }
    if (s.echo) {
      const ax = s.x + s.distance_m * Math.cos(s.axis_deg * Math.PI / 180), ay = s.y + s.distance_m * Math.sin(s.axis_deg * Math.PI / 180);
      ctx.strokeStyle = "rgb(0,150,70)"; ctx.lineWidth = 2; ctx.beginPath(); ctx.moveTo(px(s.x), py(s.y)); ctx.lineTo(px(ax), py(ay)); ctx.stroke();
      ctx.fillStyle = "rgb(0,150,70)"; ctx.beginPath(); ctx.arc(px(ax), py(ay), 4, 0, 2 * Math.PI); ctx.fill();
    }
  }
  const p = car.pose, f = car.footprint;
  ctx.save(); ctx.translate(px(p.x), py(p.y)); ctx.rotate(-p.heading_deg * Math.PI / 180);
  const L = f.length * k, W = f.width * k, C = (f.center_ahead || 0) * k;
  ctx.fillStyle = car.in_fault ? "rgba(192,57,43,.8)" : "rgba(10,110,189,.85)"; ctx.strokeStyle = "#033";
  ctx.fillRect(C - L / 2, -W / 2, L, W); ctx.strokeRect(C - L / 2, -W / 2, L, W);
  ctx.fillStyle = "#fff"; ctx.beginPath();  // the heading arrow
  ctx.moveTo(C + L / 2 - 2, 0); ctx.lineTo(C + L / 2 - L * 0.35, -W * 0.3); ctx.lineTo(C + L / 2 - L * 0.35, W * 0.3); ctx.closePath(); ctx.fill();
  ctx.restore();
  if (car.label) {
    ctx.fillStyle = "#033"; ctx.font = "11px sans-serif"; ctx.textAlign = "left";
    ctx.fillText(car.label, px(p.x) + L / 2 + 4, py(p.y) - W / 2 - 4);
  }
  for (const h of (car.line ? car.line.sensors : [])) {
    ctx.fillStyle = h.on_tape ? "#e74c3c" : "#fff"; ctx.strokeStyle = "#000"; ctx.lineWidth = 1;
    ctx.beginPath(); ctx.arc(px(h.x), py(h.y), 3.5, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
  }
}
function hilDraw(ctx, car, picked) {
  hilFit(ctx.canvas, car.arena);
  hilDrawArena(ctx, car.arena, picked);
  hilDrawCar(ctx, car);
}
)JS";

}  // namespace

json arena_json(const sim::Arena& arena, const std::vector<bool>* present) {
  json j;
  j["name"] = arena.name;
  j["width"] = arena.width_m;
  j["height"] = arena.height_m;
  j["walls"] = arena.walls;
  j["wall_thickness"] = arena.wall_thickness_m;
  j["obstacles"] = json::array();
  for (std::size_t i = 0; i < arena.obstacles.size(); ++i) {
    if (present != nullptr && i < present->size() && !(*present)[i]) continue;
    json o = obstacle_json(arena.obstacles[i], i);
    o["present"] = true;
    j["obstacles"].push_back(std::move(o));
  }
  j["tapes"] = json::array();
  for (const auto& tape : arena.tapes) {
    json points = json::array();
    for (const auto& p : tape.points_m)
      points.push_back({sim::round_to(p.x_m, 1e-4), sim::round_to(p.y_m, 1e-4)});
    j["tapes"].push_back({{"name", tape.name},
                          {"width", tape.width_m},
                          {"closed", tape.closed},
                          {"points", points}});
  }
  j["stations"] = json::array();
  for (const auto& tag : arena.tags)
    j["stations"].push_back({{"id", tag.id},
                             {"x", tag.position_m.x_m},
                             {"y", tag.position_m.y_m},
                             {"radius", tag.radius_m}});
  j["start"] = {{"x", arena.start.x_m},
                {"y", arena.start.y_m},
                {"heading_deg", sim::rad_to_deg(arena.start.heading_rad)}};
  return j;
}

std::string_view drawing_script() {
  return kScript;
}

}  // namespace hil::view
