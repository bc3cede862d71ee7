#pragma once
// The parts of the SVG picture. sim/svg.cpp lays the picture out and draws
// the arena and the runs in it, from the bottom layer up; the parts it uses:
//
//   svg_shapes.cpp  numbers, text widths, arrows and the symbols of marks
//   svg_labels.cpp  LabelPlacer: labels where they cover least
//   svg_legend.cpp  the legend under the arena
//
// Internal to hil::sim.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "sim/arena.hpp"
#include "sim/geometry.hpp"
#include "sim/trajectory.hpp"

namespace hil::sim::svg_parts {

// Colours are fixed so that pictures of different runs compare at a glance.
inline constexpr std::string_view kPaper = "#ffffff";
inline constexpr std::string_view kFloor = "#f7f4ec";
inline constexpr std::string_view kWall = "#37474f";
inline constexpr std::string_view kGridMinor = "#e2e0d8";
inline constexpr std::string_view kGridMajor = "#cfccc0";
inline constexpr std::string_view kAxisText = "#555555";
inline constexpr std::string_view kObstacleFill = "#9e9e9e";
inline constexpr std::string_view kObstacleStroke = "#616161";
inline constexpr std::string_view kTape = "#263238";
inline constexpr std::string_view kTagFill = "#ffb300";
inline constexpr std::string_view kTagStroke = "#6d4c00";
inline constexpr std::string_view kStart = "#2e7d32";
inline constexpr std::string_view kCollision = "#d50000";
inline constexpr std::string_view kText = "#212121";
/// Marks in the legend, where no vehicle owns them.
inline constexpr std::string_view kSymbol = "#546e7a";

/// Vehicle colours: none of them is the collision red, the tag amber or the
/// start green, so a path never reads as one of those.
inline constexpr std::array<std::string_view, 8> kPalette = {
    "#1565c0", "#c2185b", "#00838f", "#6a1b9a", "#ef6c00", "#5d4037", "#827717", "#3949ab"};

/// The colour of the `index`th vehicle.
inline std::string vehicle_colour(std::size_t index) {
  return std::string(kPalette[index % kPalette.size()]);
}

inline constexpr double kLabelFontPx = 12;
inline constexpr double kAxisFontPx = 11;
inline constexpr double kTitleFontPx = 18;
inline constexpr double kMarkHalfPx = 7;
inline constexpr double kPadPx = 12;

// How much it costs a label to cover one square pixel of each kind of drawing:
// covering another label or a symbol hides it, covering a line only crosses it.
inline constexpr double kCoverPath = 0.6;
inline constexpr double kCoverShape = 0.8;
inline constexpr double kCoverTape = 1.5;
inline constexpr double kCoverSymbol = 6;
inline constexpr double kCoverText = 8;

/// A point on the picture, in pixels, y down.
struct Px {
  double x = 0;
  double y = 0;
};

/// An axis-aligned box on the picture, in pixels.
struct Rect {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  double overlap(const Rect& o) const;
  double area() const { return (x1 - x0) * (y1 - y0); }
};

// ---- svg_shapes.cpp ----------------------------------------------------------

/// Fixed-point with at most three decimals, independent of the C locale, so
/// the same drawing always gives the same bytes.
std::string num(double v);

/// Width of `text` in a sans-serif face, estimated per character (in ems,
/// rounded up from DejaVu Sans): good enough to keep labels apart and the
/// legend from running off the picture.
double text_width_px(std::string_view text, double font_px);

bool finite_point(Vec2 p);
bool finite_point(const Pose& p);

/// "x,y x,y ...": the value of a points attribute.
std::string points_attr(const std::vector<Px>& points);

/// An arrow from `from` to `to` as a polygon: a shaft of `shaft_px` and a head.
std::vector<Px> arrow_polygon(Px from, Px to, double shaft_px, double head_len_px,
                              double head_half_px);

/// "collision", "stop", "station", "note".
std::string_view kind_name(MarkKind kind);
/// The kind `kind_name` names; nullopt for another word.
std::optional<MarkKind> parse_mark_kind(std::string_view name);

/// The symbol of a mark centred on `c`: a red cross for a collision whoever
/// had it, `colour` (the vehicle's) for the rest.
std::string mark_symbol(MarkKind kind, Px c, std::string_view colour);

// ---- svg_labels.cpp ----------------------------------------------------------

/// Places labels where they cover least of what is drawn, so a busy spot (a
/// station read right on a tag, a stop inside a footprint) stays readable.
/// Labels pushed away from their point get a thin leader line back to it.
class LabelPlacer {
 public:
  /// Labels stay inside `bounds` where they can.
  explicit LabelPlacer(Rect bounds) : bounds_(bounds) {}

  /// Something drawn over `r`; covering it costs `weight` per square pixel.
  void occupy(Rect r, double weight);

  /// A square of half-size `half_px` around `c`.
  void occupy_around(Px c, double half_px, double weight);

  /// A stroked line, cut into short pieces so that a diagonal does not claim
  /// its whole bounding box.
  void occupy_line(const std::vector<Px>& points, bool closed, double half_width_px, double weight);

  /// Asks for a label beside something of half-size `half_px` at `c`; labels
  /// are placed by place_all in the order asked for.
  void request(std::string text, Px c, double half_px, std::string_view colour,
               std::string_view css_class, bool centre_first = false);

  /// The labels as SVG, each where it covers least (nearer spots preferred).
  std::string place_all();

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
  static long cell(double v);
  static long long key(long cx, long cy);

  double covered(const Rect& box);
  static std::vector<Candidate> candidates(const Request& r);
  void place(const Request& r, std::string& out);

  Rect bounds_;
  std::vector<Taken> taken_;
  std::vector<std::uint64_t> stamp_;
  std::uint64_t generation_ = 0;
  std::unordered_map<long long, std::vector<std::size_t>> cells_;
  std::vector<std::size_t> large_;
  std::vector<Request> requests_;
};

// ---- svg_legend.cpp ----------------------------------------------------------

/// One legend entry: which symbol to draw, then its explanation.
struct LegendEntry {
  std::string symbol;  ///< "tape", "stop", ... or "vehicle:<index>"
  std::string text;
};

/// A row of entries under a heading ("Arena", "Marks", "Vehicles").
struct LegendSection {
  std::string heading;
  std::vector<LegendEntry> entries;
};

/// What the legend explains: the arena's parts (the grid only when
/// `grid_step_m` is above 0), the marks, and each vehicle with the length
/// and duration of its path.
std::vector<LegendSection> legend_sections(const Arena& arena,
                                           std::span<const Trajectory> trajectories,
                                           double grid_step_m);

/// The width an entry takes in a row, symbol and gap included.
double legend_entry_width(const LegendEntry& e);

/// Flows the legend rows under the arena, from `top` on a picture
/// `canvas_w` wide; with `out` it appends them there as SVG. Returns the
/// legend's height.
double layout_legend(const std::vector<LegendSection>& sections, double top, double canvas_w,
                     std::string* out);

}  // namespace hil::sim::svg_parts
