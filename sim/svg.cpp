// The SVG picture of an arena and the runs in it: the canvas laid out around
// the arena (title, axes, legend), then the layers from the floor up, then
// the labels placed where they cover least.

#include "sim/svg.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <variant>
#include <vector>

#include "base/duration.hpp"
#include "base/text.hpp"
#include "sim/svg_parts.hpp"

namespace hil::sim {
namespace svg_parts {

/// One picture: the arena's size in pixels, where it sits on the canvas,
/// and the layers drawn in order into one string.
class Renderer {
 public:
  Renderer(const Arena& arena, std::span<const Trajectory> trajectories, const SvgOptions& options)
      : arena_(arena), trajectories_(trajectories), options_(options) {
    if (!(options.pixels_per_m > 0) || !std::isfinite(options.pixels_per_m)) {
      throw std::invalid_argument("render_svg: pixels_per_m must be a positive number");
    }
    ppm_ = options.pixels_per_m;
    width_m_ = std::isfinite(arena.width_m) && arena.width_m > 0 ? arena.width_m : 0;
    height_m_ = std::isfinite(arena.height_m) && arena.height_m > 0 ? arena.height_m : 0;
    wall_px_ =
        arena.walls
            ? std::max(std::isfinite(arena.wall_thickness_m) ? arena.wall_thickness_m * ppm_ : 0.0,
                       4.0)
            : 0;
  }

  std::string render() {
    const auto legend =
        options_.legend ? legend_sections(arena_, trajectories_, options_.grid ? grid_step_m() : 0)
                        : std::vector<LegendSection>{};
    const double legend_top = lay_out(legend);
    std::string out = document_head();
    // Labels stay on the floor, off the walls and axes.
    LabelPlacer labels({left_px_, top_px_, left_px_ + width_m_ * ppm_, top_px_ + height_m_ * ppm_});
    draw_floor_and_walls(out);
    if (options_.grid) draw_grid(out);
    draw_obstacles(out, labels);
    draw_tapes(out, labels);
    draw_tags(out, labels);
    // Paths below the start arrow (every run begins on it), footprints and
    // marks above everything.
    draw_paths(out, labels);
    draw_start(out, labels);
    draw_footprints(out, labels);
    draw_marks(out, labels);
    out += "<g class=\"labels\">\n" + labels.place_all() + "</g>\n";
    if (options_.legend) {
      out += "<g class=\"legend\">\n";
      layout_legend(legend, legend_top, canvas_w_, &out);
      out += "</g>\n";
    }
    out += "</svg>\n";
    return out;
  }

 private:
  /// Sizes the canvas around the title, the arena with its walls and axes,
  /// and the legend, and finds where the arena's floor begins. Returns where
  /// the legend begins.
  double lay_out(const std::vector<LegendSection>& legend) {
    const double title_px = options_.title.empty() ? 0 : kTitleFontPx + 16;
    const double axis_left_px = options_.grid ? 48 : 0;
    const double axis_bottom_px = options_.grid ? 36 : 0;
    const double content_w = kPadPx + axis_left_px + 2 * wall_px_ + width_m_ * ppm_ + kPadPx;
    double min_w = 320;
    if (!options_.title.empty()) {
      min_w = std::max(min_w, text_width_px(options_.title, kTitleFontPx) + 2 * kPadPx);
    }
    for (const auto& section : legend) {
      for (const auto& e : section.entries)
        min_w = std::max(min_w, legend_entry_width(e) + 4 * kPadPx);
    }
    canvas_w_ = std::max(content_w, min_w);
    left_px_ = (canvas_w_ - content_w) / 2 + kPadPx + axis_left_px + wall_px_;
    top_px_ = kPadPx + title_px + wall_px_;
    const double arena_bottom_px = top_px_ + height_m_ * ppm_ + wall_px_;
    const double legend_top = arena_bottom_px + axis_bottom_px + kPadPx;
    const double legend_h =
        options_.legend ? layout_legend(legend, legend_top, canvas_w_, nullptr) : 0;
    canvas_h_ = legend_top + legend_h + (options_.legend ? kPadPx : 0);
    return legend_top;
  }

  /// The XML declaration, the <svg> element, the document's title and
  /// style, the paper and the title drawn above the arena.
  std::string document_head() const {
    std::string out;
    out += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    out += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(canvas_w_) + "\" height=\"" +
           num(canvas_h_) + "\" viewBox=\"0 0 " + num(canvas_w_) + ' ' + num(canvas_h_) +
           "\" font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\" font-size=\"" +
           num(kLabelFontPx) + "\">\n";
    const std::string doc_title = !options_.title.empty() ? options_.title : arena_.name;
    if (!doc_title.empty()) out += "<title>" + xml_escape(doc_title) + "</title>\n";
    // A white outline behind every label keeps it legible over tape and paths.
    out +=
        "<style>.halo{paint-order:stroke;stroke:#ffffff;stroke-width:3.5px;"
        "stroke-linejoin:round}</style>\n";
    out += "<rect class=\"paper\" x=\"0\" y=\"0\" width=\"" + num(canvas_w_) + "\" height=\"" +
           num(canvas_h_) + "\" fill=\"" + std::string(kPaper) + "\"/>\n";
    if (!options_.title.empty()) {
      out += "<text class=\"title\" x=\"" + num(canvas_w_ / 2) + "\" y=\"" +
             num(kPadPx + kTitleFontPx) + "\" text-anchor=\"middle\" font-size=\"" +
             num(kTitleFontPx) + "\" font-weight=\"bold\" fill=\"" + std::string(kText) + "\">" +
             xml_escape(options_.title) + "</text>\n";
    }
    return out;
  }

  Px to_px(Vec2 p) const { return {left_px_ + p.x_m * ppm_, top_px_ + (height_m_ - p.y_m) * ppm_}; }

  void draw_floor_and_walls(std::string& out) const {
    const double w = width_m_ * ppm_;
    const double h = height_m_ * ppm_;
    if (arena_.walls) {
      out += "<rect class=\"wall\" x=\"" + num(left_px_ - wall_px_) + "\" y=\"" +
             num(top_px_ - wall_px_) + "\" width=\"" + num(w + 2 * wall_px_) + "\" height=\"" +
             num(h + 2 * wall_px_) + "\" fill=\"" + std::string(kWall) + "\"/>\n";
    }
    out += "<rect class=\"floor\" x=\"" + num(left_px_) + "\" y=\"" + num(top_px_) + "\" width=\"" +
           num(w) + "\" height=\"" + num(h) + "\" fill=\"" + std::string(kFloor) + "\"" +
           (arena_.walls ? std::string() : " stroke=\"#9e9e9e\" stroke-dasharray=\"6 4\"") + "/>\n";
  }

  /// 0.5 m, or coarser where lines that close would be a smear.
  double grid_step_m() const {
    double grid_m = 0.5;
    while (grid_m * ppm_ < 16)
      grid_m *= 2;
    return grid_m;
  }

  /// Grid lines, and metre labels on a step that leaves room for the numbers.
  void draw_grid(std::string& out) const {
    const double grid_m = grid_step_m();
    double label_m = grid_m;
    while (label_m * ppm_ < 44)
      label_m *= 2;
    const auto count = [](double extent_m, double step_m) {
      return static_cast<long>(std::floor(extent_m / step_m + 1e-9));
    };
    out += "<g class=\"grid\" stroke-width=\"1\">\n";
    const double x0 = left_px_, x1 = left_px_ + width_m_ * ppm_;
    const double y0 = top_px_, y1 = top_px_ + height_m_ * ppm_;
    for (long i = 1;; ++i) {
      const double x_m = static_cast<double>(i) * grid_m;
      if (x_m >= width_m_ - 1e-9) break;
      const bool major = std::fabs(x_m - std::round(x_m)) < 1e-9;
      out += "<line x1=\"" + num(x0 + x_m * ppm_) + "\" y1=\"" + num(y0) + "\" x2=\"" +
             num(x0 + x_m * ppm_) + "\" y2=\"" + num(y1) + "\" stroke=\"" +
             std::string(major ? kGridMajor : kGridMinor) + "\"/>\n";
    }
    for (long i = 1;; ++i) {
      const double y_m = static_cast<double>(i) * grid_m;
      if (y_m >= height_m_ - 1e-9) break;
      const bool major = std::fabs(y_m - std::round(y_m)) < 1e-9;
      const double y = to_px({0, y_m}).y;
      out += "<line x1=\"" + num(x0) + "\" y1=\"" + num(y) + "\" x2=\"" + num(x1) + "\" y2=\"" +
             num(y) + "\" stroke=\"" + std::string(major ? kGridMajor : kGridMinor) + "\"/>\n";
    }
    out += "</g>\n";

    out += "<g class=\"axes\" font-size=\"" + num(kAxisFontPx) + "\" fill=\"" +
           std::string(kAxisText) + "\">\n";
    const double below = y1 + wall_px_ + 14;
    for (long i = 0; i <= count(width_m_, label_m); ++i) {
      const double x_m = static_cast<double>(i) * label_m;
      out += "<text x=\"" + num(x0 + x_m * ppm_) + "\" y=\"" + num(below) +
             "\" text-anchor=\"middle\">" + num(x_m) + "</text>\n";
    }
    const double left = x0 - wall_px_ - 5;
    for (long i = 0; i <= count(height_m_, label_m); ++i) {
      const double y_m = static_cast<double>(i) * label_m;
      out += "<text x=\"" + num(left) + "\" y=\"" + num(to_px({0, y_m}).y + 4) +
             "\" text-anchor=\"end\">" + num(y_m) + "</text>\n";
    }
    out += "<text x=\"" + num((x0 + x1) / 2) + "\" y=\"" + num(below + 16) +
           "\" text-anchor=\"middle\">x (m)</text>\n";
    const double yx = x0 - wall_px_ - 36;
    const double yy = (y0 + y1) / 2;
    out += "<text x=\"" + num(yx) + "\" y=\"" + num(yy) + "\" text-anchor=\"middle\" transform=\"" +
           "rotate(-90 " + num(yx) + ' ' + num(yy) + ")\">y (m)</text>\n";
    out += "</g>\n";
  }

  void draw_obstacles(std::string& out, LabelPlacer& labels) const {
    for (const auto& obstacle : arena_.obstacles) {
      std::visit(
          [&](const auto& o) {
            using T = std::decay_t<decltype(o)>;
            const Px c = to_px(o.center_m);
            double shape_w_px = 0;
            double half_px = 0;
            if constexpr (std::is_same_v<T, BoxObstacle>) {
              const Pose frame{o.center_m.x_m, o.center_m.y_m, o.angle_rad};
              const double hw = o.width_m / 2, hh = o.height_m / 2;
              std::vector<Px> corners;
              for (const Vec2 k : {Vec2{-hw, -hh}, Vec2{hw, -hh}, Vec2{hw, hh}, Vec2{-hw, hh}}) {
                corners.push_back(to_px(frame.to_arena(k)));
              }
              out += "<polygon class=\"obstacle\" points=\"" + points_attr(corners) + "\" fill=\"" +
                     std::string(kObstacleFill) + "\" stroke=\"" + std::string(kObstacleStroke) +
                     "\" stroke-width=\"1.5\">";
              shape_w_px = std::min(o.width_m, o.height_m) * ppm_;
              if (std::fabs(std::sin(o.angle_rad)) < 1e-6) shape_w_px = o.width_m * ppm_;
              half_px = std::max(o.width_m, o.height_m) * ppm_ / 2;
            } else {
              out += "<circle class=\"obstacle\" cx=\"" + num(c.x) + "\" cy=\"" + num(c.y) +
                     "\" r=\"" + num(o.radius_m * ppm_) + "\" fill=\"" +
                     std::string(kObstacleFill) + "\" stroke=\"" + std::string(kObstacleStroke) +
                     "\" stroke-width=\"1.5\">";
              shape_w_px = 2 * o.radius_m * ppm_;
              half_px = o.radius_m * ppm_;
            }
            out += "<title>" + xml_escape(o.name) + "</title>";
            out += std::is_same_v<T, BoxObstacle> ? "</polygon>\n" : "</circle>\n";
            if (!o.name.empty() && finite_point(o.center_m)) {
              // Inside the shape when it fits, beside it when the shape is small.
              const bool fits = text_width_px(o.name, kLabelFontPx) + 6 <= shape_w_px;
              labels.request(o.name, c, fits ? 0 : half_px, kText, "obstacle-label", fits);
            }
          },
          obstacle);
    }
  }

  void draw_tapes(std::string& out, LabelPlacer& labels) const {
    for (const auto& tape : arena_.tapes) {
      std::vector<Px> points;
      for (const auto& p : tape.points_m) {
        if (finite_point(p)) points.push_back(to_px(p));
      }
      const double stroke = std::max(2.0, std::isfinite(tape.width_m) ? tape.width_m * ppm_ : 0.0);
      const char* element = tape.closed ? "polygon" : "polyline";
      out += std::string("<") + element + " class=\"tape\" points=\"" + points_attr(points) +
             "\" fill=\"none\" stroke=\"" + std::string(kTape) + "\" stroke-width=\"" +
             num(stroke) + "\" stroke-linejoin=\"round\" stroke-linecap=\"round\"><title>" +
             xml_escape(tape.name) + "</title></" + element + ">\n";
      labels.occupy_line(points, tape.closed, stroke / 2 + 1, kCoverTape);
    }
  }

  static double tag_radius_px(const RfidTag& tag, double ppm) {
    return std::max(5.0, std::isfinite(tag.radius_m) ? tag.radius_m * ppm : 0.0);
  }

  void draw_tags(std::string& out, LabelPlacer& labels) const {
    for (const auto& tag : arena_.tags) {
      const Px c = to_px(tag.position_m);
      const double r = tag_radius_px(tag, ppm_);
      out += "<circle class=\"tag\" cx=\"" + num(c.x) + "\" cy=\"" + num(c.y) + "\" r=\"" + num(r) +
             "\" fill=\"" + std::string(kTagFill) + "\" stroke=\"" + std::string(kTagStroke) +
             "\" stroke-width=\"1.5\"><title>RFID " + xml_escape(tag.id) + "</title></circle>\n";
      if (finite_point(tag.position_m)) labels.occupy_around(c, r, kCoverSymbol);
    }
    for (const auto& tag : arena_.tags) {
      if (!finite_point(tag.position_m)) continue;
      labels.request(tag.id, to_px(tag.position_m), tag_radius_px(tag, ppm_), "#5d4300",
                     "tag-label");
    }
  }

  void draw_start(std::string& out, LabelPlacer& labels) const {
    if (!finite_point(arena_.start)) return;
    const Px from = to_px(arena_.start.position());
    const double len_px = std::max(0.2 * ppm_, 26.0);
    const Px to{from.x + len_px * std::cos(arena_.start.heading_rad),
                from.y - len_px * std::sin(arena_.start.heading_rad)};
    out += "<g class=\"start\">";
    out += "<circle cx=\"" + num(from.x) + "\" cy=\"" + num(from.y) + "\" r=\"4\" fill=\"" +
           std::string(kStart) + "\" stroke=\"#ffffff\" stroke-width=\"1.5\"/>";
    out += "<polygon points=\"" + points_attr(arrow_polygon(from, to, 4, 12, 7)) + "\" fill=\"" +
           std::string(kStart) + "\" stroke=\"#ffffff\" stroke-width=\"1\"/>";
    out += "</g>\n";
    labels.occupy_line({from, to}, false, 6, kCoverSymbol);
    labels.request("start", from, 6, kStart, "start-label");
  }

  void draw_paths(std::string& out, LabelPlacer& labels) const {
    for (std::size_t i = 0; i < trajectories_.size(); ++i) {
      const auto& t = trajectories_[i];
      const std::string colour = vehicle_colour(i);
      std::vector<Px> points;
      for (const auto& s : t.samples) {
        if (finite_point(s.pose.position())) points.push_back(to_px(s.pose.position()));
      }
      out += "<g class=\"trajectory\" data-vehicle=\"" + xml_escape(t.vehicle) + "\">";
      if (points.size() >= 2) {
        out += "<polyline class=\"path\" points=\"" + points_attr(points) +
               "\" fill=\"none\" stroke=\"" + colour +
               "\" stroke-width=\"3\" stroke-opacity=\"0.85\" stroke-linejoin=\"round\" "
               "stroke-linecap=\"round\"/>";
        labels.occupy_line(points, false, 2.5, kCoverPath);
      }
      if (!points.empty()) {
        // Hollow ring where the path began.
        out += "<circle class=\"path-start\" cx=\"" + num(points.front().x) + "\" cy=\"" +
               num(points.front().y) + "\" r=\"4.5\" fill=\"#ffffff\" stroke=\"" + colour +
               "\" stroke-width=\"2\"/>";
      }
      out += "</g>\n";
    }
  }

  /// Each car's footprint and heading at its last pose.
  void draw_footprints(std::string& out, LabelPlacer& labels) const {
    for (std::size_t i = 0; i < trajectories_.size(); ++i) {
      const auto& t = trajectories_[i];
      const std::string colour = vehicle_colour(i);
      const TrajectorySample* last = nullptr;
      for (const auto& s : t.samples) {
        if (finite_point(s.pose)) last = &s;
      }
      if (last == nullptr) continue;
      const Pose& pose = last->pose;
      const double hl = (std::isfinite(t.length_m) ? t.length_m : 0) / 2;
      const double hw = (std::isfinite(t.width_m) ? t.width_m : 0) / 2;
      std::vector<Px> corners;
      for (const Vec2 k : {Vec2{-hl, -hw}, Vec2{hl, -hw}, Vec2{hl, hw}, Vec2{-hl, hw}}) {
        corners.push_back(to_px(pose.to_arena(k)));
      }
      // The heading arrow sticks out of the footprint's front, where no mark
      // at the car's centre hides it.
      const Px centre = to_px(pose.position());
      const Px ahead{std::cos(pose.heading_rad), -std::sin(pose.heading_rad)};
      const double front_px = hl * ppm_;
      const Px tail{centre.x + ahead.x * std::max(front_px - 8, 0.0),
                    centre.y + ahead.y * std::max(front_px - 8, 0.0)};
      const Px tip{centre.x + ahead.x * (front_px + 18), centre.y + ahead.y * (front_px + 18)};
      out += "<g class=\"footprint\"><polygon points=\"" + points_attr(corners) + "\" fill=\"" +
             colour + "\" fill-opacity=\"0.22\" stroke=\"" + colour +
             "\" stroke-width=\"2\" stroke-linejoin=\"round\"/>";
      out += "<polygon class=\"heading\" points=\"" +
             points_attr(arrow_polygon(tail, tip, 3.5, 11, 7)) + "\" fill=\"" + colour +
             "\" stroke=\"#ffffff\" stroke-width=\"0.8\"/></g>\n";
      labels.occupy_line(corners, true, 1.5, kCoverShape);
      labels.occupy_line({tail, tip}, false, 6, kCoverSymbol);
    }
  }

  /// The marks of every run, each labelled with what happened and when; all
  /// of them are in place before the first label looks for room.
  void draw_marks(std::string& out, LabelPlacer& labels) const {
    for (std::size_t i = 0; i < trajectories_.size(); ++i) {
      for (const auto& m : trajectories_[i].marks) {
        if (finite_point(m.position_m)) {
          labels.occupy_around(to_px(m.position_m), kMarkHalfPx + 3, kCoverSymbol);
        }
      }
    }
    for (std::size_t i = 0; i < trajectories_.size(); ++i) {
      const auto& t = trajectories_[i];
      const std::string colour = vehicle_colour(i);
      for (const auto& m : t.marks) {
        if (!finite_point(m.position_m)) continue;
        const Px c = to_px(m.position_m);
        out += "<g class=\"mark " + std::string(kind_name(m.kind)) + "\" fill=\"none\">" +
               mark_symbol(m.kind, c, colour) + "</g>\n";
        const std::string text = (m.label.empty() ? std::string(kind_name(m.kind)) : m.label) +
                                 ' ' + seconds_text(m.time, 1);
        labels.request(text, c, kMarkHalfPx + 2,
                       m.kind == MarkKind::collision ? kCollision : std::string_view(colour),
                       "mark-label");
      }
    }
  }

  const Arena& arena_;
  std::span<const Trajectory> trajectories_;
  const SvgOptions& options_;
  double ppm_ = 200;
  double width_m_ = 0;
  double height_m_ = 0;
  double wall_px_ = 0;
  double canvas_w_ = 0;
  double canvas_h_ = 0;
  double left_px_ = 0;
  double top_px_ = 0;
};

}  // namespace svg_parts

std::string render_svg(const Arena& arena, std::span<const Trajectory> trajectories,
                       const SvgOptions& options) {
  return svg_parts::Renderer(arena, trajectories, options).render();
}

}  // namespace hil::sim
