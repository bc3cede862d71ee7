#include "sim/svg.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace hil::sim {
namespace {

// The length of the UTF-8 sequence starting at `i` and its code point, or
// 0 when the bytes there are not valid UTF-8.
std::size_t utf8_at(std::string_view s, std::size_t i, char32_t& cp) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const unsigned char c = b(0);
  std::size_t n = 0;
  if (c < 0x80) {
    cp = c;
    return 1;
  }
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
    cp = c & 0x1F;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    cp = c & 0x0F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    cp = c & 0x07;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b(k) & 0x3F);
  }
  // Overlong forms, surrogates and values past U+10FFFF are not characters.
  if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10FFFF)) ||
      (cp >= 0xD800 && cp <= 0xDFFF))
    return 0;
  return n;
}

// Colours are fixed so that pictures of different runs compare at a glance.
constexpr std::string_view kPaper = "#ffffff";
constexpr std::string_view kFloor = "#f7f4ec";
constexpr std::string_view kWall = "#37474f";
constexpr std::string_view kGridMinor = "#e2e0d8";
constexpr std::string_view kGridMajor = "#cfccc0";
constexpr std::string_view kAxisText = "#555555";
constexpr std::string_view kObstacleFill = "#9e9e9e";
constexpr std::string_view kObstacleStroke = "#616161";
constexpr std::string_view kTape = "#263238";
constexpr std::string_view kTagFill = "#ffb300";
constexpr std::string_view kTagStroke = "#6d4c00";
constexpr std::string_view kStart = "#2e7d32";
constexpr std::string_view kCollision = "#d50000";
constexpr std::string_view kText = "#212121";
constexpr std::string_view kSymbol = "#546e7a";  // marks in the legend, where no vehicle owns them

// Vehicle colours: none of them is the collision red, the tag amber or the
// start green, so a path never reads as one of those.
constexpr std::array<std::string_view, 8> kPalette = {"#1565c0", "#c2185b", "#00838f", "#6a1b9a",
                                                      "#ef6c00", "#5d4037", "#827717", "#3949ab"};

constexpr double kLabelFontPx = 12;
constexpr double kAxisFontPx = 11;
constexpr double kTitleFontPx = 18;
constexpr double kMarkHalfPx = 7;
constexpr double kPadPx = 12;

/// Fixed-point with at most three decimals, independent of the C locale, so
/// the same drawing always gives the same bytes.
std::string num(double v) {
  if (!std::isfinite(v)) v = 0;
  v = std::clamp(v, -1e12, 1e12);
  std::array<char, 64> buf{};
  const auto result =
      std::to_chars(buf.data(), buf.data() + buf.size(), v, std::chars_format::fixed, 3);
  std::string s(buf.data(), result.ptr);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0')
      s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

/// Seconds with one decimal, as people read them on a label ("12.3 s").
std::string seconds_text(Duration d) {
  double s = to_seconds(d);
  if (!std::isfinite(s)) s = 0;
  std::array<char, 64> buf{};
  const auto result = std::to_chars(buf.data(), buf.data() + buf.size(), std::clamp(s, -1e12, 1e12),
                                    std::chars_format::fixed, 1);
  std::string text(buf.data(), result.ptr);
  if (text == "-0.0") text = "0.0";
  return text + " s";
}

/// Width of `text` in a sans-serif face, estimated per character (in ems,
/// rounded up from DejaVu Sans): good enough to keep labels apart and the
/// legend from running off the picture.
double text_width_px(std::string_view text, double font_px) {
  double ems = 0;
  for (char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if ((u & 0xC0) == 0x80) continue;  // UTF-8 continuation byte
    if (std::string_view(" .,:;'!|()[]ijlft").find(c) != std::string_view::npos) {
      ems += 0.34;
    } else if (std::string_view("mwMW@%").find(c) != std::string_view::npos) {
      ems += 0.9;
    } else if (u >= 'A' && u <= 'Z') {
      ems += 0.72;
    } else {
      ems += 0.62;
    }
  }
  return ems * font_px;
}

bool finite_point(Vec2 p) {
  return std::isfinite(p.x_m) && std::isfinite(p.y_m);
}
bool finite_point(const Pose& p) {
  return finite_point(p.position()) && std::isfinite(p.heading_rad);
}

struct Px {
  double x = 0;
  double y = 0;
};

struct Rect {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  double overlap(const Rect& o) const {
    const double w = std::min(x1, o.x1) - std::max(x0, o.x0);
    const double h = std::min(y1, o.y1) - std::max(y0, o.y0);
    return w > 0 && h > 0 ? w * h : 0;
  }
  double area() const { return (x1 - x0) * (y1 - y0); }
};

std::string points_attr(const std::vector<Px>& points) {
  std::string out;
  for (const auto& p : points) {
    if (!out.empty()) out += ' ';
    out += num(p.x) + ',' + num(p.y);
  }
  return out;
}

/// An arrow from `from` to `to` as a polygon: a shaft of `shaft_px` and a head.
std::vector<Px> arrow_polygon(Px from, Px to, double shaft_px, double head_len_px,
                              double head_half_px) {
  const double dx = to.x - from.x;
  const double dy = to.y - from.y;
  const double len = std::hypot(dx, dy);
  if (len <= 0) return {};
  const double ux = dx / len, uy = dy / len;  // along
  const double nx = -uy, ny = ux;             // across
  const double head = std::min(head_len_px, len * 0.8);
  const Px neck{to.x - ux * head, to.y - uy * head};
  const double s = shaft_px / 2;
  return {{from.x + nx * s, from.y + ny * s},
          {neck.x + nx * s, neck.y + ny * s},
          {neck.x + nx * head_half_px, neck.y + ny * head_half_px},
          to,
          {neck.x - nx * head_half_px, neck.y - ny * head_half_px},
          {neck.x - nx * s, neck.y - ny * s},
          {from.x - nx * s, from.y - ny * s}};
}

std::string_view kind_name(MarkKind kind) {
  switch (kind) {
    case MarkKind::collision:
      return "collision";
    case MarkKind::stop:
      return "stop";
    case MarkKind::station:
      return "station";
    case MarkKind::note:
      return "note";
  }
  return "note";
}

/// The symbol of a mark centred on `c`: a red cross for a collision whoever
/// had it, the vehicle's colour for the rest.
std::string mark_symbol(MarkKind kind, Px c, std::string_view colour) {
  const double s = kMarkHalfPx;
  std::string out;
  switch (kind) {
    case MarkKind::collision: {
      const std::string d = "M" + num(c.x - s) + ',' + num(c.y - s) + " L" + num(c.x + s) + ',' +
                            num(c.y + s) + " M" + num(c.x - s) + ',' + num(c.y + s) + " L" +
                            num(c.x + s) + ',' + num(c.y - s);
      // White underneath so the cross stays visible on the dark tape.
      out +=
          "<path d=\"" + d + "\" stroke=\"#ffffff\" stroke-width=\"6\" stroke-linecap=\"round\"/>";
      out += "<path d=\"" + d + "\" stroke=\"" + std::string(kCollision) +
             "\" stroke-width=\"3.5\" stroke-linecap=\"round\"/>";
      break;
    }
    case MarkKind::stop: {
      std::vector<Px> octagon;
      const double r = s + 3;
      for (int k = 0; k < 8; ++k) {
        const double a = std::numbers::pi / 8 + k * std::numbers::pi / 4;
        octagon.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a)});
      }
      out += "<polygon points=\"" + points_attr(octagon) + "\" fill=\"" + std::string(colour) +
             "\" stroke=\"#ffffff\" stroke-width=\"1.5\"/>";
      break;
    }
    case MarkKind::station: {
      const double r = s + 2;
      const std::vector<Px> diamond = {
          {c.x, c.y - r}, {c.x + r, c.y}, {c.x, c.y + r}, {c.x - r, c.y}};
      out += "<polygon points=\"" + points_attr(diamond) + "\" fill=\"" + std::string(colour) +
             "\" stroke=\"#ffffff\" stroke-width=\"1.5\"/>";
      break;
    }
    case MarkKind::note:
      out += "<circle cx=\"" + num(c.x) + "\" cy=\"" + num(c.y) + "\" r=\"" + num(s - 2) +
             "\" fill=\"" + std::string(colour) + "\" stroke=\"#ffffff\" stroke-width=\"1.5\"/>";
      break;
  }
  return out;
}

// How much it costs a label to cover one square pixel of each kind of drawing:
// covering another label or a symbol hides it, covering a line only crosses it.
constexpr double kCoverPath = 0.6;
constexpr double kCoverShape = 0.8;
constexpr double kCoverTape = 1.5;
constexpr double kCoverSymbol = 6;
constexpr double kCoverText = 8;

/// Places labels where they cover least of what is drawn, so a busy spot (a
/// station read right on a tag, a stop inside a footprint) stays readable.
/// Labels pushed away from their point get a thin leader line back to it.
class LabelPlacer {
 public:
  explicit LabelPlacer(Rect bounds) : bounds_(bounds) {}

  void occupy(Rect r, double weight) {
    const std::size_t index = taken_.size();
    taken_.push_back({r, weight});
    stamp_.push_back(0);
    const long cx0 = cell(r.x0), cx1 = cell(r.x1), cy0 = cell(r.y0), cy1 = cell(r.y1);
    if ((cx1 - cx0 + 1) * (cy1 - cy0 + 1) > 4096) {
      large_.push_back(index);
      return;
    }
    for (long cx = cx0; cx <= cx1; ++cx) {
      for (long cy = cy0; cy <= cy1; ++cy)
        cells_[key(cx, cy)].push_back(index);
    }
  }

  void occupy_around(Px c, double half_px, double weight) {
    occupy({c.x - half_px, c.y - half_px, c.x + half_px, c.y + half_px}, weight);
  }

  /// A stroked line, cut into short pieces so that a diagonal does not claim
  /// its whole bounding box.
  void occupy_line(const std::vector<Px>& points, bool closed, double half_width_px,
                   double weight) {
    const std::size_t n = points.size();
    for (std::size_t i = 0; i + 1 < n + (closed && n > 2 ? 1 : 0); ++i) {
      const Px a = points[i];
      const Px b = points[(i + 1) % n];
      const double len = std::hypot(b.x - a.x, b.y - a.y);
      const int pieces = std::max(1, static_cast<int>(std::ceil(len / 12)));
      for (int k = 0; k < pieces; ++k) {
        const double t0 = static_cast<double>(k) / pieces;
        const double t1 = static_cast<double>(k + 1) / pieces;
        const Px p{a.x + (b.x - a.x) * t0, a.y + (b.y - a.y) * t0};
        const Px q{a.x + (b.x - a.x) * t1, a.y + (b.y - a.y) * t1};
        occupy({std::min(p.x, q.x) - half_width_px, std::min(p.y, q.y) - half_width_px,
                std::max(p.x, q.x) + half_width_px, std::max(p.y, q.y) + half_width_px},
               weight);
      }
    }
  }

  /// Asks for a label beside something of half-size `half_px` at `c`; labels
  /// are placed by place_all in the order asked for.
  void request(std::string text, Px c, double half_px, std::string_view colour,
               std::string_view css_class, bool centre_first = false) {
    requests_.push_back(
        {std::move(text), c, half_px, std::string(colour), std::string(css_class), centre_first});
  }

  /// The labels as SVG, each where it covers least (nearer spots preferred).
  std::string place_all() {
    std::string out;
    for (const auto& r : requests_)
      place(r, out);
    return out;
  }

 private:
  struct Taken {
    Rect rect;
    double weight;
  };
  struct Request {
    std::string text;
    Px at;
    double half_px;
    std::string colour;
    std::string css_class;
    bool centre_first;
  };
  struct Candidate {
    double x, baseline;
    char anchor;  // 's'tart, 'm'iddle, 'e'nd
    int ring;
  };

  static constexpr double kCellPx = 32;
  static long cell(double v) { return static_cast<long>(std::floor(v / kCellPx)); }
  static long long key(long cx, long cy) {
    return (static_cast<long long>(cx) << 32) ^ static_cast<long long>(cy & 0xffffffffL);
  }

  double covered(const Rect& box) {
    ++generation_;
    double cost = 0;
    const auto add = [&](std::size_t index) {
      if (stamp_[index] == generation_) return;
      stamp_[index] = generation_;
      cost += taken_[index].weight * box.overlap(taken_[index].rect);
    };
    for (long cx = cell(box.x0); cx <= cell(box.x1); ++cx) {
      for (long cy = cell(box.y0); cy <= cell(box.y1); ++cy) {
        const auto it = cells_.find(key(cx, cy));
        if (it == cells_.end()) continue;
        for (const std::size_t index : it->second)
          add(index);
      }
    }
    for (const std::size_t index : large_)
      add(index);
    return cost;
  }

  void place(const Request& r, std::string& out) {
    const double w = text_width_px(r.text, kLabelFontPx);
    const Px c = r.at;
    std::vector<Candidate> candidates;
    if (r.centre_first) candidates.push_back({c.x, c.y + 4, 'm', 0});
    for (int ring = 0; ring < 3; ++ring) {
      const double d = r.half_px + 4 + 18 * ring;
      const double e = d * 0.75;
      candidates.push_back({c.x + d, c.y + 4, 's', ring});
      candidates.push_back({c.x + e, c.y - e - 1, 's', ring});
      candidates.push_back({c.x + e, c.y + e + 10, 's', ring});
      candidates.push_back({c.x - d, c.y + 4, 'e', ring});
      candidates.push_back({c.x - e, c.y - e - 1, 'e', ring});
      candidates.push_back({c.x - e, c.y + e + 10, 'e', ring});
      candidates.push_back({c.x, c.y - d - 3, 'm', ring});
      candidates.push_back({c.x, c.y + d + 11, 'm', ring});
    }
    std::size_t best = 0;
    double best_cost = std::numeric_limits<double>::infinity();
    Rect best_box;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const auto& k = candidates[i];
      const double x0 = k.anchor == 's' ? k.x : (k.anchor == 'm' ? k.x - w / 2 : k.x - w);
      const Rect box{x0 - 2, k.baseline - 11, x0 + w + 2, k.baseline + 3};
      double cost = covered(box) + 60.0 * k.ring;
      cost += 20 * (box.area() - box.overlap(bounds_));  // off the arena is worst
      if (cost < best_cost - 1e-9) {
        best_cost = cost;
        best = i;
        best_box = box;
      }
    }
    occupy(best_box, kCoverText);
    const auto& k = candidates[best];
    if (k.ring > 0) {
      // From the edge of the thing labelled to the nearest point of the label.
      const Px near{std::clamp(c.x, best_box.x0, best_box.x1),
                    std::clamp(c.y, best_box.y0 + 2, best_box.y1 - 2)};
      const double dx = near.x - c.x, dy = near.y - c.y;
      const double len = std::hypot(dx, dy);
      if (len > r.half_px + 3) {
        const Px from{c.x + dx / len * (r.half_px + 2), c.y + dy / len * (r.half_px + 2)};
        out += "<line class=\"leader\" x1=\"" + num(from.x) + "\" y1=\"" + num(from.y) +
               "\" x2=\"" + num(near.x) + "\" y2=\"" + num(near.y) + "\" stroke=\"" + r.colour +
               "\" stroke-width=\"1\"/>\n";
      }
    }
    const char* anchor = k.anchor == 's' ? "start" : (k.anchor == 'm' ? "middle" : "end");
    out += "<text class=\"" + r.css_class + " halo\" x=\"" + num(k.x) + "\" y=\"" +
           num(k.baseline) + "\" text-anchor=\"" + anchor + "\" fill=\"" + r.colour + "\">" +
           xml_escape(r.text) + "</text>\n";
  }

  Rect bounds_;
  std::vector<Taken> taken_;
  std::vector<std::uint64_t> stamp_;
  std::uint64_t generation_ = 0;
  std::unordered_map<long long, std::vector<std::size_t>> cells_;
  std::vector<std::size_t> large_;
  std::vector<Request> requests_;
};

/// One legend entry: which symbol to draw, then its explanation.
struct LegendEntry {
  std::string symbol;  ///< "tape", "stop", ... or "vehicle:<index>"
  std::string text;
};

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
    const double title_px = options_.title.empty() ? 0 : kTitleFontPx + 16;
    const double axis_left_px = options_.grid ? 48 : 0;
    const double axis_bottom_px = options_.grid ? 36 : 0;
    const double arena_w_px = width_m_ * ppm_;
    const double arena_h_px = height_m_ * ppm_;
    const double content_w = kPadPx + axis_left_px + 2 * wall_px_ + arena_w_px + kPadPx;
    double min_w = 320;
    if (!options_.title.empty()) {
      min_w = std::max(min_w, text_width_px(options_.title, kTitleFontPx) + 2 * kPadPx);
    }
    const auto legend = options_.legend ? legend_entries() : std::vector<LegendSection>{};
    for (const auto& section : legend) {
      for (const auto& e : section.entries)
        min_w = std::max(min_w, entry_width(e) + 4 * kPadPx);
    }
    canvas_w_ = std::max(content_w, min_w);
    left_px_ = (canvas_w_ - content_w) / 2 + kPadPx + axis_left_px + wall_px_;
    top_px_ = kPadPx + title_px + wall_px_;
    const double arena_bottom_px = top_px_ + arena_h_px + wall_px_;
    const double legend_top = arena_bottom_px + axis_bottom_px + kPadPx;
    const double legend_h = options_.legend ? layout_legend(legend, legend_top, false) : 0;
    canvas_h_ = legend_top + legend_h + (options_.legend ? kPadPx : 0);

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

    // Labels stay on the floor, off the walls and axes.
    LabelPlacer labels({left_px_, top_px_, left_px_ + arena_w_px, top_px_ + arena_h_px});
    draw_floor_and_walls(out);
    if (options_.grid) draw_grid(out);
    draw_obstacles(out, labels);
    draw_tapes(out, labels);
    draw_tags(out, labels);
    // Paths below the start arrow (every run begins on it), footprints and
    // marks above everything.
    draw_paths(out, labels);
    draw_start(out, labels);
    draw_footprints_and_marks(out, labels);
    out += "<g class=\"labels\">\n" + labels.place_all() + "</g>\n";
    if (options_.legend) {
      out += "<g class=\"legend\">\n";
      legend_svg_.clear();
      layout_legend(legend, legend_top, true);
      out += legend_svg_;
      out += "</g>\n";
    }
    out += "</svg>\n";
    return out;
  }

 private:
  struct LegendSection {
    std::string heading;
    std::vector<LegendEntry> entries;
  };

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
      const std::string colour(kPalette[i % kPalette.size()]);
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

  void draw_footprints_and_marks(std::string& out, LabelPlacer& labels) const {
    for (std::size_t i = 0; i < trajectories_.size(); ++i) {
      const auto& t = trajectories_[i];
      const std::string colour(kPalette[i % kPalette.size()]);
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
    for (std::size_t i = 0; i < trajectories_.size(); ++i) {
      for (const auto& m : trajectories_[i].marks) {
        if (finite_point(m.position_m)) {
          labels.occupy_around(to_px(m.position_m), kMarkHalfPx + 3, kCoverSymbol);
        }
      }
    }
    for (std::size_t i = 0; i < trajectories_.size(); ++i) {
      const auto& t = trajectories_[i];
      const std::string colour(kPalette[i % kPalette.size()]);
      for (const auto& m : t.marks) {
        if (!finite_point(m.position_m)) continue;
        const Px c = to_px(m.position_m);
        out += "<g class=\"mark " + std::string(kind_name(m.kind)) + "\" fill=\"none\">" +
               mark_symbol(m.kind, c, colour) + "</g>\n";
        const std::string text = (m.label.empty() ? std::string(kind_name(m.kind)) : m.label) +
                                 ' ' + seconds_text(m.time);
        labels.request(text, c, kMarkHalfPx + 2,
                       m.kind == MarkKind::collision ? kCollision : std::string_view(colour),
                       "mark-label");
      }
    }
  }

  // ---- legend ----------------------------------------------------------------

  static constexpr double kSymbolW = 24;
  static constexpr double kRowH = 22;

  static double entry_width(const LegendEntry& e) {
    return kSymbolW + 6 + text_width_px(e.text, kLabelFontPx) + 16;
  }

  std::vector<LegendSection> legend_entries() const {
    std::vector<LegendSection> sections;
    LegendSection arena{"Arena", {}};
    arena.entries.push_back({"floor", "floor"});
    if (arena_.walls) arena.entries.push_back({"wall", "wall"});
    arena.entries.push_back({"obstacle", "obstacle"});
    arena.entries.push_back({"tape", "floor tape"});
    arena.entries.push_back({"tag", "RFID tag (id)"});
    arena.entries.push_back({"start", "start pose"});
    if (options_.grid) arena.entries.push_back({"grid", "grid " + num(grid_step_m()) + " m"});
    sections.push_back(arena);

    LegendSection marks{"Marks", {}};
    marks.entries.push_back({"collision", "collision"});
    marks.entries.push_back({"stop", "stop"});
    marks.entries.push_back({"station", "station read"});
    marks.entries.push_back({"note", "note"});
    marks.entries.push_back({"footprint", "car at its last pose"});
    marks.entries.push_back({"path-start", "path start"});
    sections.push_back(marks);

    if (!trajectories_.empty()) {
      LegendSection cars{"Vehicles", {}};
      for (std::size_t i = 0; i < trajectories_.size(); ++i) {
        const auto& t = trajectories_[i];
        double path_m = 0;
        const TrajectorySample* first = nullptr;
        const TrajectorySample* prev = nullptr;
        for (const auto& s : t.samples) {
          if (!finite_point(s.pose.position())) continue;
          if (first == nullptr) first = &s;
          if (prev != nullptr) path_m += length(s.pose.position() - prev->pose.position());
          prev = &s;
        }
        std::string text = t.vehicle.empty() ? "vehicle " + std::to_string(i + 1) : t.vehicle;
        if (first == nullptr) {
          text += ": no samples";
        } else {
          std::array<char, 32> buf{};
          const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), std::min(path_m, 1e9),
                                       std::chars_format::fixed, 2);
          text += ": " + std::string(buf.data(), r.ptr) + " m in " +
                  seconds_text(prev->time - first->time);
        }
        cars.entries.push_back({"vehicle:" + std::to_string(i), text});
      }
      sections.push_back(cars);
    }
    return sections;
  }

  std::string legend_symbol(const std::string& kind, Px c) const {
    const auto rect = [&](double w, double h, std::string_view fill, std::string_view extra) {
      return "<rect x=\"" + num(c.x - w / 2) + "\" y=\"" + num(c.y - h / 2) + "\" width=\"" +
             num(w) + "\" height=\"" + num(h) + "\" fill=\"" + std::string(fill) + "\"" +
             std::string(extra) + "/>";
    };
    if (kind == "floor") return rect(20, 14, kFloor, " stroke=\"#bdbdbd\"");
    if (kind == "wall") return rect(20, 14, kWall, "");
    if (kind == "obstacle") {
      return rect(20, 14, kObstacleFill,
                  " stroke=\"" + std::string(kObstacleStroke) + "\" stroke-width=\"1.5\"");
    }
    if (kind == "tape") {
      return "<line x1=\"" + num(c.x - 10) + "\" y1=\"" + num(c.y) + "\" x2=\"" + num(c.x + 10) +
             "\" y2=\"" + num(c.y) + "\" stroke=\"" + std::string(kTape) +
             "\" stroke-width=\"5\"/>";
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
    if (kind == "collision") return mark_symbol(MarkKind::collision, c, kSymbol);
    if (kind == "stop") return mark_symbol(MarkKind::stop, c, kSymbol);
    if (kind == "station") return mark_symbol(MarkKind::station, c, kSymbol);
    if (kind == "note") return mark_symbol(MarkKind::note, c, kSymbol);
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
    const std::size_t index = std::stoul(kind.substr(8));
    const std::string colour(kPalette[index % kPalette.size()]);
    return "<line x1=\"" + num(c.x - 11) + "\" y1=\"" + num(c.y) + "\" x2=\"" + num(c.x + 11) +
           "\" y2=\"" + num(c.y) + "\" stroke=\"" + colour +
           "\" stroke-width=\"4\" stroke-linecap=\"round\"/>";
  }

  /// Flows the legend rows under the arena; with `draw` it writes them to
  /// legend_svg_. Returns the legend's height.
  double layout_legend(const std::vector<LegendSection>& sections, double top, bool draw) {
    const double x_begin = kPadPx + 8;
    const double x_end = canvas_w_ - kPadPx - 8;
    const double heading_w = 74;
    double y = top + 8 + kRowH / 2;
    for (const auto& section : sections) {
      double x = x_begin;
      if (draw) {
        legend_svg_ += "<text x=\"" + num(x) + "\" y=\"" + num(y + 4) +
                       "\" font-weight=\"bold\" fill=\"" + std::string(kText) + "\">" +
                       xml_escape(section.heading) + "</text>\n";
      }
      x += heading_w;
      for (const auto& e : section.entries) {
        const double w = entry_width(e);
        if (x + w > x_end && x > x_begin + heading_w) {
          x = x_begin + heading_w;
          y += kRowH;
        }
        if (draw) {
          legend_svg_ += "<g class=\"legend-entry\" fill=\"none\">" +
                         legend_symbol(e.symbol, {x + kSymbolW / 2, y}) + "</g>";
          legend_svg_ += "<text x=\"" + num(x + kSymbolW + 6) + "\" y=\"" + num(y + 4) +
                         "\" fill=\"" + std::string(kText) + "\">" + xml_escape(e.text) +
                         "</text>\n";
        }
        x += w;
      }
      y += kRowH;
    }
    const double height = y - kRowH / 2 - top + 4;
    if (draw) {
      legend_svg_ += "<rect class=\"legend-frame\" x=\"" + num(kPadPx) + "\" y=\"" + num(top) +
                     "\" width=\"" + num(canvas_w_ - 2 * kPadPx) + "\" height=\"" + num(height) +
                     "\" fill=\"none\" stroke=\"#d6d6d6\" rx=\"4\"/>\n";
    }
    return height;
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
  std::string legend_svg_;
};

}  // namespace

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    char32_t cp = 0;
    const std::size_t n = utf8_at(text, i, cp);
    if (n == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD for a byte that is not UTF-8
      ++i;
      continue;
    }
    switch (cp) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        if ((cp < 0x20 && cp != '\t' && cp != '\n' && cp != '\r') || cp == 0xFFFE || cp == 0xFFFF) {
          // XML 1.0 cannot carry these even as references.
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\x%02X", static_cast<unsigned>(cp & 0xFF));
          out += buf;
        } else {
          out.append(text.substr(i, n));
        }
    }
    i += n;
  }
  return out;
}

std::string render_svg(const Arena& arena, std::span<const Trajectory> trajectories,
                       const SvgOptions& options) {
  return Renderer(arena, trajectories, options).render();
}

}  // namespace hil::sim
