// The legend under the arena: a symbol and its meaning for every colour and
// mark the picture uses, and one entry per vehicle.

#include <algorithm>
#include <charconv>

#include "base/duration.hpp"
#include "base/text.hpp"
#include "sim/svg_parts.hpp"

namespace hil::sim::svg_parts {
namespace {

constexpr double kLegendSymbolW = 24;
constexpr double kLegendRowH = 22;

/// "car-1: 2.35 m in 12.3 s" (or "vehicle 2: no samples"): how far the
/// `index`th vehicle drove and for how long.
std::string vehicle_summary(const Trajectory& t, std::size_t index) {
  double path_m = 0;
  const TrajectorySample* first = nullptr;
  const TrajectorySample* prev = nullptr;
  for (const auto& s : t.samples) {
    if (!finite_point(s.pose.position())) continue;
    if (first == nullptr) first = &s;
    if (prev != nullptr) path_m += length(s.pose.position() - prev->pose.position());
    prev = &s;
  }
  std::string text = t.vehicle.empty() ? "vehicle " + std::to_string(index + 1) : t.vehicle;
  if (first == nullptr) return text + ": no samples";
  std::array<char, 32> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), std::min(path_m, 1e9),
                               std::chars_format::fixed, 2);
  return text + ": " + std::string(buf.data(), r.ptr) + " m in " +
         seconds_text(prev->time - first->time, 1);
}

/// The symbol of an arena part in the legend, or "" for a kind that is not one.
std::string arena_symbol(const std::string& kind, Px c) {
  const auto rect = [&](double w, double h, std::string_view fill, std::string_view extra) {
    return "<rect x=\"" + num(c.x - w / 2) + "\" y=\"" + num(c.y - h / 2) + "\" width=\"" + num(w) +
           "\" height=\"" + num(h) + "\" fill=\"" + std::string(fill) + "\"" + std::string(extra) +
           "/>";
  };
  if (kind == "floor") return rect(20, 14, kFloor, " stroke=\"#bdbdbd\"");
  if (kind == "wall") return rect(20, 14, kWall, "");
  if (kind == "obstacle") {
    return rect(20, 14, kObstacleFill,
                " stroke=\"" + std::string(kObstacleStroke) + "\" stroke-width=\"1.5\"");
  }
  if (kind == "tape") {
    return "<line x1=\"" + num(c.x - 10) + "\" y1=\"" + num(c.y) + "\" x2=\"" + num(c.x + 10) +
           "\" y2=\"" + num(c.y) + "\" stroke=\"" + std::string(kTape) + "\" stroke-width=\"5\"/>";
  }
  if (kind == "tag") {
    return "<circle cx=\"" + num(c.x) + "\" cy=\"" + num(c.y) + "\" r=\"6\" fill=\"" +
           std::string(kTagFill) + "\" stroke=\"" + std::string(kTagStroke) +
           "\" stroke-width=\"1.5\"/>";
  }
  if (kind == "start") {
    return "<polygon points=\"" +
           points_attr(arrow_polygon({c.x - 10, c.y}, {c.x + 11, c.y}, 4, 9, 6)) + "\" fill=\"" +
           std::string(kStart) + "\"/>";
  }
  if (kind == "grid") {
    return rect(20, 14, kFloor, " stroke=\"#bdbdbd\"") + "<line x1=\"" + num(c.x) + "\" y1=\"" +
           num(c.y - 7) + "\" x2=\"" + num(c.x) + "\" y2=\"" + num(c.y + 7) + "\" stroke=\"" +
           std::string(kGridMajor) + "\"/><line x1=\"" + num(c.x - 10) + "\" y1=\"" + num(c.y) +
           "\" x2=\"" + num(c.x + 10) + "\" y2=\"" + num(c.y) + "\" stroke=\"" +
           std::string(kGridMajor) + "\"/>";
  }
  return "";
}

/// The symbol of a mark, of a vehicle's parts or of a vehicle ("vehicle:<index>").
std::string run_symbol(const std::string& kind, Px c) {
  if (const auto mark = parse_mark_kind(kind)) return mark_symbol(*mark, c, kSymbol);
  if (kind == "footprint") {
    const std::vector<Px> box = {
        {c.x - 11, c.y - 6}, {c.x + 5, c.y - 6}, {c.x + 5, c.y + 6}, {c.x - 11, c.y + 6}};
    return "<polygon points=\"" + points_attr(box) + "\" fill=\"" + std::string(kSymbol) +
           "\" fill-opacity=\"0.22\" stroke=\"" + std::string(kSymbol) +
           "\" stroke-width=\"2\"/><polygon points=\"" +
           points_attr(arrow_polygon({c.x - 3, c.y}, {c.x + 12, c.y}, 3, 7, 5)) + "\" fill=\"" +
           std::string(kSymbol) + "\"/>";
  }
  if (kind == "path-start") {
    return "<circle cx=\"" + num(c.x) + "\" cy=\"" + num(c.y) +
           "\" r=\"4.5\" fill=\"#ffffff\" stroke=\"" + std::string(kSymbol) +
           "\" stroke-width=\"2\"/>";
  }
  // vehicle:<index>
  const std::string colour = vehicle_colour(std::stoul(kind.substr(8)));
  return "<line x1=\"" + num(c.x - 11) + "\" y1=\"" + num(c.y) + "\" x2=\"" + num(c.x + 11) +
         "\" y2=\"" + num(c.y) + "\" stroke=\"" + colour +
         "\" stroke-width=\"4\" stroke-linecap=\"round\"/>";
}

std::string legend_symbol(const std::string& kind, Px c) {
  std::string symbol = arena_symbol(kind, c);
  return symbol.empty() ? run_symbol(kind, c) : symbol;
}

}  // namespace

std::vector<LegendSection> legend_sections(const Arena& arena,
                                           std::span<const Trajectory> trajectories,
                                           double grid_step_m) {
  std::vector<LegendSection> sections;
  LegendSection parts{"Arena", {}};
  parts.entries.push_back({"floor", "floor"});
  if (arena.walls) parts.entries.push_back({"wall", "wall"});
  parts.entries.push_back({"obstacle", "obstacle"});
  parts.entries.push_back({"tape", "floor tape"});
  parts.entries.push_back({"tag", "RFID tag (id)"});
  parts.entries.push_back({"start", "start pose"});
  if (grid_step_m > 0) parts.entries.push_back({"grid", "grid " + num(grid_step_m) + " m"});
  sections.push_back(parts);

  LegendSection marks{"Marks", {}};
  marks.entries.push_back({"collision", "collision"});
  marks.entries.push_back({"stop", "stop"});
  marks.entries.push_back({"station", "station read"});
  marks.entries.push_back({"note", "note"});
  marks.entries.push_back({"footprint", "car at its last pose"});
  marks.entries.push_back({"path-start", "path start"});
  sections.push_back(marks);

  if (!trajectories.empty()) {
    LegendSection cars{"Vehicles", {}};
    for (std::size_t i = 0; i < trajectories.size(); ++i)
      cars.entries.push_back({"vehicle:" + std::to_string(i), vehicle_summary(trajectories[i], i)});
    sections.push_back(cars);
  }
  return sections;
}

double legend_entry_width(const LegendEntry& e) {
  return kLegendSymbolW + 6 + text_width_px(e.text, kLabelFontPx) + 16;
}

double layout_legend(const std::vector<LegendSection>& sections, double top, double canvas_w,
                     std::string* out) {
  const double x_begin = kPadPx + 8;
  const double x_end = canvas_w - kPadPx - 8;
  const double heading_w = 74;
  double y = top + 8 + kLegendRowH / 2;
  for (const auto& section : sections) {
    double x = x_begin;
    if (out != nullptr) {
      *out += "<text x=\"" + num(x) + "\" y=\"" + num(y + 4) + "\" font-weight=\"bold\" fill=\"" +
              std::string(kText) + "\">" + xml_escape(section.heading) + "</text>\n";
    }
    x += heading_w;
    for (const auto& e : section.entries) {
      const double w = legend_entry_width(e);
      if (x + w > x_end && x > x_begin + heading_w) {
        x = x_begin + heading_w;
        y += kLegendRowH;
      }
      if (out != nullptr) {
        *out += "<g class=\"legend-entry\" fill=\"none\">" +
                legend_symbol(e.symbol, {x + kLegendSymbolW / 2, y}) + "</g>";
        *out += "<text x=\"" + num(x + kLegendSymbolW + 6) + "\" y=\"" + num(y + 4) + "\" fill=\"" +
                std::string(kText) + "\">" + xml_escape(e.text) + "</text>\n";
      }
      x += w;
    }
    y += kLegendRowH;
  }
  const double height = y - kLegendRowH / 2 - top + 4;
  if (out != nullptr) {
    *out += "<rect class=\"legend-frame\" x=\"" + num(kPadPx) + "\" y=\"" + num(top) +
            "\" width=\"" + num(canvas_w - 2 * kPadPx) + "\" height=\"" + num(height) +
            "\" fill=\"none\" stroke=\"#d6d6d6\" rx=\"4\"/>\n";
  }
  return height;
}

}  // namespace hil::sim::svg_parts
