// Pictures of arenas and runs: a standalone, well-formed SVG that shows every
// part of the arena once, with y up, escaped names and the same bytes each time.
//
// With HIL_WRITE_IMAGES=<dir> set, the example run of the built-in warehouse
// is also written to <dir>/warehouse.svg, to look at every kind of mark.

#include "sim/svg.hpp"

#include <gtest/gtest.h>
#include <limits>

#include <clocale>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <locale>
#include <numbers>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hil::sim {
namespace {

using std::chrono::milliseconds;

struct Px {
  double x = 0;
  double y = 0;
};

/// Checks that every element opened is closed, in order, and names the first
/// one that is not. Self-closing tags, the XML declaration and comments need no
/// partner.
std::string tag_balance_problem(const std::string& svg) {
  std::vector<std::string> open;
  std::size_t pos = 0;
  while ((pos = svg.find('<', pos)) != std::string::npos) {
    if (svg.compare(pos, 2, "<?") == 0) {
      pos = svg.find("?>", pos);
      if (pos == std::string::npos) return "unterminated <?";
      continue;
    }
    if (svg.compare(pos, 4, "<!--") == 0) {
      pos = svg.find("-->", pos);
      if (pos == std::string::npos) return "unterminated comment";
      continue;
    }
    const std::size_t end = svg.find('>', pos);
    if (end == std::string::npos) return "unterminated tag at " + std::to_string(pos);
    const std::string tag = svg.substr(pos + 1, end - pos - 1);
    pos = end + 1;
    if (tag.empty()) return "empty tag";
    if (tag[0] == '/') {
      const std::string name = tag.substr(1);
      if (open.empty()) return "</" + name + "> closes nothing";
      if (open.back() != name) return "</" + name + "> closes <" + open.back() + ">";
      open.pop_back();
      continue;
    }
    if (tag.back() == '/') continue;
    open.push_back(tag.substr(0, tag.find_first_of(" \t\n")));
  }
  if (!open.empty()) return "<" + open.back() + "> never closed";
  return "";
}

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t pos = text.find(needle); pos != std::string::npos;
       pos = text.find(needle, pos + needle.size())) {
    ++n;
  }
  return n;
}

/// The value of attribute `name` in the first element that contains `marker`
/// in its opening tag.
std::optional<double> attribute_of(const std::string& svg, const std::string& marker,
                                   const std::string& name, std::size_t nth = 0) {
  std::size_t pos = 0;
  for (std::size_t i = 0; i <= nth; ++i) {
    pos = svg.find(marker, i == 0 ? 0 : pos + 1);
    if (pos == std::string::npos) return std::nullopt;
  }
  const std::size_t begin = svg.rfind('<', pos);
  const std::size_t end = svg.find('>', pos);
  const std::string tag = svg.substr(begin, end - begin);
  const std::string key = " " + name + "=\"";
  const std::size_t at = tag.find(key);
  if (at == std::string::npos) return std::nullopt;
  return std::stod(tag.substr(at + key.size()));
}

/// Text of every <text> element whose class list contains `css_class`.
std::vector<std::string> texts_of_class(const std::string& svg, const std::string& css_class) {
  std::vector<std::string> out;
  const std::regex text_re("<text class=\"" + css_class + "[^\"]*\"[^>]*>([^<]*)</text>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), text_re);
       it != std::sregex_iterator(); ++it) {
    out.push_back((*it)[1]);
  }
  return out;
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

// ---- the example run shown in docs/images/warehouse.svg ---------------------

/// Arc-length walk along a closed tape, starting at `start`.
class LoopWalk {
 public:
  LoopWalk(const Tape& tape, Vec2 start) {
    // The built-in loop ends at the start pose, so walk from the last point.
    points_.push_back(start);
    for (const auto& p : tape.points_m) {
      if (!(p == start)) points_.push_back(p);
    }
    points_.push_back(start);
    cumulative_.push_back(0);
    for (std::size_t i = 1; i < points_.size(); ++i) {
      cumulative_.push_back(cumulative_.back() + length(points_[i] - points_[i - 1]));
    }
  }

  /// Arc length at which the walk first passes `p` (which lies on the tape).
  double arc_length_at(Vec2 p) const {
    for (std::size_t i = 1; i < points_.size(); ++i) {
      if (distance_to_segment(p, points_[i - 1], points_[i]) < 1e-6) {
        return cumulative_[i - 1] + length(p - points_[i - 1]);
      }
    }
    throw std::logic_error("point not on the loop");
  }

  /// Pose at arc length `s_m`, `left_m` to the left of the centre line.
  Pose pose_at(double s_m, double left_m) const {
    std::size_t i = 1;
    while (i + 1 < points_.size() && cumulative_[i] < s_m)
      ++i;
    const Vec2 a = points_[i - 1];
    const Vec2 b = points_[i];
    const double seg = cumulative_[i] - cumulative_[i - 1];
    const double t = seg > 0 ? (s_m - cumulative_[i - 1]) / seg : 0;
    const Vec2 dir = (1.0 / seg) * (b - a);
    const Vec2 p = a + t * (b - a) + left_m * Vec2{-dir.y_m, dir.x_m};
    return {p.x_m, p.y_m, std::atan2(dir.y_m, dir.x_m)};
  }

 private:
  std::vector<Vec2> points_;
  std::vector<double> cumulative_;
};

Duration at_seconds(double s) {
  return milliseconds(std::lround(s * 1000));
}

/// car1 follows the loop counter-clockwise from the start pose, reads 001,
/// is bumped by car2 on the right straight, loses the line in the next bend
/// and stops at 002; car2 drives up the right side into it.
std::vector<Trajectory> example_run(const Arena& arena) {
  const LoopWalk walk(arena.tapes.at(0), arena.start.position());
  const double speed_mps = 0.25;
  const double s_station = walk.arc_length_at({2.0, 0.6});
  const double s_bump = walk.arc_length_at({3.2, 1.5});
  const double s_stop = walk.arc_length_at({2.0, 2.4});
  const double s_lost = s_bump + 0.75;

  Trajectory car1;
  car1.vehicle = "car1";
  for (double s = 0; s <= s_stop + 1e-9; s += 0.05) {
    // A line follower weaves a little about the tape; it drifts outwards where
    // it lost the line and is pushed outwards by the bump.
    double left_m = 0.01 * std::sin(2 * std::numbers::pi * s / 0.7);
    left_m -= 0.07 * std::exp(-std::pow((s - s_lost - 0.1) / 0.18, 2));
    left_m += 0.04 * std::exp(-std::pow((s - s_bump - 0.12) / 0.1, 2));
    const Pose pose = walk.pose_at(std::min(s, s_stop), left_m);
    car1.samples.push_back({at_seconds(s / speed_mps), pose});
  }
  car1.marks.push_back(
      {at_seconds(s_station / speed_mps), {2.0, 0.6}, MarkKind::station, "station 001"});
  car1.marks.push_back(
      {at_seconds(s_bump / speed_mps), {3.33, 1.52}, MarkKind::collision, "collision car2"});
  car1.marks.push_back({at_seconds(s_lost / speed_mps), walk.pose_at(s_lost, -0.06).position(),
                        MarkKind::note, "line lost"});
  car1.marks.push_back({at_seconds(s_stop / speed_mps), {2.0, 2.4}, MarkKind::stop, "stop"});

  Trajectory car2;
  car2.vehicle = "car2";
  // A quadratic curve from the lower right corner, heading up, to where its
  // front corner meets car1's right side.
  const Vec2 p0{3.72, 0.3}, p1{3.72, 1.17}, p2{3.44, 1.43};
  const double t_start = s_bump / speed_mps - 6.0;
  for (int k = 0; k <= 24; ++k) {
    const double u = k / 24.0;
    const Vec2 p = (1 - u) * (1 - u) * p0 + 2 * (1 - u) * u * p1 + u * u * p2;
    const Vec2 d = 2 * (1 - u) * (p1 - p0) + 2 * u * (p2 - p1);
    car2.samples.push_back(
        {at_seconds(t_start + 6.0 * u), {p.x_m, p.y_m, std::atan2(d.y_m, d.x_m)}});
  }
  car2.marks.push_back({at_seconds(s_bump / speed_mps + 0.3), p2, MarkKind::stop, "stop"});
  return {car1, car2};
}

SvgOptions example_options() {
  SvgOptions options;
  options.title = "Built-in warehouse: car1 along the loop, car2 bumping into it";
  return options;
}

// ---- tests --------------------------------------------------------------------

TEST(Svg, WarehouseIsAStandaloneWellFormedDocument) {
  const std::string svg = render_svg(default_warehouse_arena(), {});
  std::string body = svg;
  if (body.rfind("<?xml", 0) == 0) body = body.substr(body.find("?>") + 2);
  body.erase(0, body.find_first_not_of(" \n"));
  EXPECT_EQ(body.rfind("<svg", 0), 0u);
  EXPECT_EQ(svg.substr(svg.find_last_not_of(" \n") - 5, 6), "</svg>");
  EXPECT_NE(svg.find("xmlns=\"http://www.w3.org/2000/svg\""), std::string::npos);
  EXPECT_EQ(tag_balance_problem(svg), "");

  const auto width = attribute_of(svg, "<svg", "width");
  const auto height = attribute_of(svg, "<svg", "height");
  ASSERT_TRUE(width && height);
  // 4 m x 3 m at 200 px/m, plus walls, axes and legend around it.
  EXPECT_GT(*width, 800);
  EXPECT_GT(*height, 600);
  EXPECT_NE(svg.find("viewBox=\"0 0 "), std::string::npos);
}

TEST(Svg, BalanceCheckerNoticesBrokenNesting) {
  EXPECT_EQ(tag_balance_problem("<svg><g><rect/></g></svg>"), "");
  EXPECT_NE(tag_balance_problem("<svg><g></svg>"), "");
  EXPECT_NE(tag_balance_problem("<svg><g></g>"), "");
  EXPECT_NE(tag_balance_problem("<svg></g></svg>"), "");
}

TEST(Svg, OneElementPerObstacleTapeAndTagWithTheirNames) {
  const Arena arena = default_warehouse_arena();
  const std::string svg = render_svg(arena, {});
  EXPECT_EQ(count(svg, "class=\"obstacle\""), arena.obstacles.size());
  EXPECT_EQ(count(svg, "class=\"tape\""), arena.tapes.size());
  EXPECT_EQ(count(svg, "class=\"tag\""), arena.tags.size());
  EXPECT_EQ(count(svg, "class=\"wall\""), 1u);
  EXPECT_EQ(count(svg, "class=\"start\""), 1u);

  const auto tag_labels = texts_of_class(svg, "tag-label");
  EXPECT_EQ(tag_labels.size(), 2u);
  EXPECT_TRUE(contains(tag_labels, "001"));
  EXPECT_TRUE(contains(tag_labels, "002"));
  const auto obstacle_labels = texts_of_class(svg, "obstacle-label");
  EXPECT_TRUE(contains(obstacle_labels, "shelf"));
  EXPECT_TRUE(contains(obstacle_labels, "pillar"));
}

TEST(Svg, ArenaYIsUpInThePicture) {
  Arena arena;
  arena.width_m = 4;
  arena.height_m = 3;
  arena.tags.push_back({"bottom", {1.0, 0.0}, 0.05});
  arena.tags.push_back({"top", {1.0, 3.0}, 0.05});
  arena.tags.push_back({"right", {4.0, 1.5}, 0.05});
  SvgOptions options;
  options.pixels_per_m = 100;
  const std::string svg = render_svg(arena, {}, options);

  const auto floor_x = attribute_of(svg, "class=\"floor\"", "x");
  const auto floor_y = attribute_of(svg, "class=\"floor\"", "y");
  const auto floor_w = attribute_of(svg, "class=\"floor\"", "width");
  const auto floor_h = attribute_of(svg, "class=\"floor\"", "height");
  ASSERT_TRUE(floor_x && floor_y && floor_w && floor_h);
  EXPECT_DOUBLE_EQ(*floor_w, 400);
  EXPECT_DOUBLE_EQ(*floor_h, 300);

  const auto bottom_cy = attribute_of(svg, "class=\"tag\"", "cy", 0);
  const auto top_cy = attribute_of(svg, "class=\"tag\"", "cy", 1);
  const auto bottom_cx = attribute_of(svg, "class=\"tag\"", "cx", 0);
  const auto right_cx = attribute_of(svg, "class=\"tag\"", "cx", 2);
  ASSERT_TRUE(bottom_cy && top_cy && bottom_cx && right_cx);
  // y = 0 is the floor's lower edge, y = 3 m its upper edge, 300 px above.
  EXPECT_NEAR(*bottom_cy, *floor_y + *floor_h, 1e-3);
  EXPECT_NEAR(*top_cy, *floor_y, 1e-3);
  EXPECT_NEAR(*bottom_cy - *top_cy, 300, 1e-3);
  // x is not flipped.
  EXPECT_NEAR(*bottom_cx, *floor_x + 100, 1e-3);
  EXPECT_NEAR(*right_cx, *floor_x + 400, 1e-3);
}

TEST(Svg, NamesAreEscapedForXml) {
  Arena arena;
  arena.name = "a & b";
  arena.obstacles.push_back(BoxObstacle{"<A&B>", {1.0, 1.0}, 0.4, 0.4, 0});
  arena.tags.push_back({"\"7\"", {2.0, 1.0}, 0.05});
  Trajectory t;
  t.vehicle = "car <1>";
  t.samples.push_back({Duration{0}, {0.5, 0.5, 0}});
  t.samples.push_back({milliseconds(1000), {1.5, 0.5, 0}});
  t.marks.push_back({milliseconds(1000), {1.5, 0.5}, MarkKind::note, "x<y & \"z\""});
  const std::vector<Trajectory> runs{t};
  SvgOptions options;
  options.title = "R&D <test>";
  const std::string svg = render_svg(arena, runs, options);

  EXPECT_EQ(tag_balance_problem(svg), "");
  EXPECT_EQ(svg.find("<A&B>"), std::string::npos);
  EXPECT_NE(svg.find("&lt;A&amp;B&gt;"), std::string::npos);
  EXPECT_NE(svg.find("&quot;7&quot;"), std::string::npos);
  EXPECT_NE(svg.find("car &lt;1&gt;"), std::string::npos);
  EXPECT_NE(svg.find("x&lt;y &amp; &quot;z&quot; 1.0 s"), std::string::npos);
  EXPECT_NE(svg.find("R&amp;D &lt;test&gt;"), std::string::npos);
  // Every & starts an entity.
  EXPECT_EQ(std::regex_search(svg, std::regex("&(?!(amp|lt|gt|quot|#39);)")), false);
}

// A name typed in a legacy code page (here "Sklad" in Windows-1251) or with
// a control character must still give a document every XML reader opens.
TEST(Svg, NamesThatAreNotUtf8OrHoldControlsStillGiveWellFormedXml) {
  Arena arena;
  arena.obstacles.push_back(BoxObstacle{"\xD1\xEA\xEB\xE0\xE4", {1.0, 1.0}, 0.4, 0.4, 0});
  arena.tags.push_back({"bell\x07", {2.0, 1.0}, 0.05});
  const std::string svg = render_svg(arena, {}, SvgOptions{});

  EXPECT_EQ(tag_balance_problem(svg), "");
  const std::string replacement = "\xEF\xBF\xBD";
  EXPECT_NE(svg.find("<title>" + replacement + replacement + replacement + replacement +
                     replacement + "</title>"),
            std::string::npos);
  EXPECT_NE(svg.find("bell\\x07"), std::string::npos);
  // Apart from the replacement characters the document is plain ASCII
  // without control characters other than line breaks.
  std::string rest;
  for (std::size_t i = 0; i < svg.size();) {
    if (svg.compare(i, replacement.size(), replacement) == 0) {
      i += replacement.size();
      continue;
    }
    rest += svg[i++];
  }
  for (char c : rest) {
    const auto byte = static_cast<unsigned char>(c);
    EXPECT_TRUE(byte == '\n' || (byte >= 0x20 && byte < 0x80)) << "byte " << int{byte};
  }
}

TEST(Svg, SameInputGivesTheSameBytes) {
  const Arena arena = default_warehouse_arena();
  const auto runs = example_run(arena);
  const std::string first = render_svg(arena, runs, example_options());
  const std::string second = render_svg(arena, runs, example_options());
  EXPECT_EQ(first, second);
}

/// A C++ locale that writes 1234.5 as "1.234,5", as German users have it.
struct DecimalComma : std::numpunct<char> {
  char do_decimal_point() const override { return ','; }
  char do_thousands_sep() const override { return '.'; }
  std::string do_grouping() const override { return "\3"; }
};

TEST(Svg, NumbersIgnoreTheLocale) {
  const Arena arena = default_warehouse_arena();
  const auto runs = example_run(arena);
  const std::string before = render_svg(arena, runs, example_options());

  const std::locale previous =
      std::locale::global(std::locale(std::locale::classic(), new DecimalComma));
  // The C locale too, where one with a decimal comma is installed.
  bool c_locale_changed = false;
  for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8"}) {
    if (std::setlocale(LC_ALL, name) != nullptr) {
      c_locale_changed = true;
      break;
    }
  }
  const std::string after = render_svg(arena, runs, example_options());
  std::locale::global(previous);
  if (c_locale_changed) std::setlocale(LC_ALL, "C");
  EXPECT_EQ(before, after);
}

TEST(Svg, NumbersHaveAtMostThreeDecimals) {
  const Arena arena = default_warehouse_arena();
  const std::string svg = render_svg(arena, example_run(arena), example_options());
  EXPECT_FALSE(std::regex_search(svg, std::regex("[0-9]\\.[0-9]{4}")));
  EXPECT_EQ(svg.find("e+"), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
}

TEST(Svg, EmptyArenaStillRenders) {
  Arena arena;
  arena.walls = false;
  const std::string svg = render_svg(arena, {});
  EXPECT_EQ(tag_balance_problem(svg), "");
  EXPECT_EQ(count(svg, "class=\"tape\""), 0u);
  EXPECT_EQ(count(svg, "class=\"obstacle\""), 0u);
  EXPECT_EQ(count(svg, "class=\"tag\""), 0u);
  EXPECT_EQ(count(svg, "class=\"wall\""), 0u);
  EXPECT_EQ(count(svg, "class=\"floor\""), 1u);

  // A zero-sized arena (not validated) gives a picture, not a crash.
  Arena nothing;
  nothing.width_m = 0;
  nothing.height_m = std::nan("");
  EXPECT_EQ(tag_balance_problem(render_svg(nothing, {})), "");
}

TEST(Svg, TrajectoryWithZeroOrOneSampleIsDrawnWithoutAPath) {
  const Arena arena = default_warehouse_arena();
  Trajectory none;
  none.vehicle = "parked";
  none.marks.push_back({Duration{0}, {1.0, 1.0}, MarkKind::note, "never moved"});
  Trajectory one;
  one.vehicle = "single";
  one.samples.push_back({milliseconds(500), {1.0, 2.0, 1.0}});
  const std::vector<Trajectory> runs{none, one};
  const std::string svg = render_svg(arena, runs);

  EXPECT_EQ(tag_balance_problem(svg), "");
  EXPECT_EQ(count(svg, "class=\"path\""), 0u);
  // Only the one with a pose has a footprint; the other still shows its mark.
  EXPECT_EQ(count(svg, "class=\"footprint\""), 1u);
  EXPECT_TRUE(contains(texts_of_class(svg, "mark-label"), "never moved 0.0 s"));
  EXPECT_NE(svg.find("parked: no samples"), std::string::npos);
}

TEST(Svg, TrajectoriesHavePathsFootprintsAndLabelledMarks) {
  const Arena arena = default_warehouse_arena();
  const auto runs = example_run(arena);
  const std::string svg = render_svg(arena, runs, example_options());

  EXPECT_EQ(count(svg, "class=\"path\""), 2u);
  EXPECT_EQ(count(svg, "class=\"footprint\""), 2u);
  EXPECT_EQ(count(svg, "class=\"heading\""), 2u);
  EXPECT_EQ(count(svg, "class=\"mark collision\""), 1u);
  EXPECT_EQ(count(svg, "class=\"mark stop\""), 2u);
  EXPECT_EQ(count(svg, "class=\"mark station\""), 1u);
  EXPECT_EQ(count(svg, "class=\"mark note\""), 1u);

  const auto labels = texts_of_class(svg, "mark-label");
  ASSERT_EQ(labels.size(), 5u);
  EXPECT_TRUE(contains(labels, "station 001 3.2 s"));
  for (const auto& label : labels)
    EXPECT_TRUE(std::regex_search(label, std::regex(" [0-9]+\\.[0-9] s$"))) << label;

  // Each vehicle its own colour.
  const std::regex path_colour("class=\"path\"[^>]* stroke=\"(#[0-9a-f]{6})\"");
  std::vector<std::string> colours;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), path_colour);
       it != std::sregex_iterator(); ++it) {
    colours.push_back((*it)[1]);
  }
  ASSERT_EQ(colours.size(), 2u);
  EXPECT_NE(colours[0], colours[1]);

  // The legend names both vehicles and explains every mark.
  EXPECT_NE(svg.find(">car1: "), std::string::npos);
  EXPECT_NE(svg.find(">car2: "), std::string::npos);
  for (const char* meaning : {">collision<", ">stop<", ">station read<", ">note<", ">floor tape<",
                              ">RFID tag (id)<", ">start pose<"}) {
    EXPECT_NE(svg.find(meaning), std::string::npos) << meaning;
  }
}

TEST(Svg, FootprintAndHeadingSitAtTheLastPose) {
  Arena arena;  // 4 m x 3 m
  Trajectory t;
  t.vehicle = "car";
  t.length_m = 0.3;
  t.width_m = 0.2;
  t.samples.push_back({Duration{0}, {0.5, 0.5, 0}});
  t.samples.push_back({milliseconds(2000), {2.0, 1.5, std::numbers::pi / 2}});
  const std::vector<Trajectory> runs{t};
  SvgOptions options;
  options.pixels_per_m = 100;
  const std::string svg = render_svg(arena, runs, options);

  const auto floor_x = attribute_of(svg, "class=\"floor\"", "x");
  const auto floor_y = attribute_of(svg, "class=\"floor\"", "y");
  ASSERT_TRUE(floor_x && floor_y);
  const auto points_of = [&](const std::string& marker) {
    const std::size_t at = svg.find(marker);
    const std::size_t begin = svg.find("points=\"", at) + 8;
    std::vector<Px> points;
    std::stringstream in(svg.substr(begin, svg.find('"', begin) - begin));
    Px p;
    char comma = 0;
    while (in >> p.x >> comma >> p.y)
      points.push_back(p);
    return points;
  };
  const auto corners = points_of("class=\"footprint\"");
  ASSERT_EQ(corners.size(), 4u);
  double x0 = std::numeric_limits<double>::infinity(),
         x1 = -std::numeric_limits<double>::infinity(),
         y0 = std::numeric_limits<double>::infinity(),
         y1 = -std::numeric_limits<double>::infinity();
  for (const auto& p : corners) {
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  // Heading up the arena: 0.3 m long upwards, 0.2 m wide across, centred on the pose.
  EXPECT_NEAR(x1 - x0, 20, 1e-2);
  EXPECT_NEAR(y1 - y0, 30, 1e-2);
  EXPECT_NEAR((x0 + x1) / 2, *floor_x + 200, 1e-2);
  EXPECT_NEAR((y0 + y1) / 2, *floor_y + 150, 1e-2);
  // The arrow points up in the picture, beyond the front of the footprint.
  const auto arrow = points_of("class=\"heading\"");
  ASSERT_FALSE(arrow.empty());
  const double tip_y =
      std::min_element(arrow.begin(), arrow.end(), [](Px a, Px b) { return a.y < b.y; })->y;
  EXPECT_LT(tip_y, y0 - 5);
}

TEST(Svg, LegendSitsBelowTheArenaAndCanBeLeftOut) {
  const Arena arena = default_warehouse_arena();
  const std::string with = render_svg(arena, {});
  const auto floor_bottom = *attribute_of(with, "class=\"floor\"", "y") +
                            *attribute_of(with, "class=\"floor\"", "height");
  const auto legend_top = attribute_of(with, "class=\"legend-frame\"", "y");
  ASSERT_TRUE(legend_top);
  EXPECT_GT(*legend_top, floor_bottom);

  SvgOptions bare;
  bare.legend = false;
  bare.grid = false;
  const std::string without = render_svg(arena, {}, bare);
  EXPECT_EQ(without.find("legend"), std::string::npos);
  EXPECT_EQ(without.find("class=\"grid\""), std::string::npos);
  EXPECT_LT(*attribute_of(without, "<svg", "height"), *attribute_of(with, "<svg", "height"));
}

TEST(Svg, TapeIsDrawnAtItsWidthButNeverThinnerThanTwoPixels) {
  const Arena arena = default_warehouse_arena();
  const auto stroke_at = [&](double pixels_per_m) {
    SvgOptions options;
    options.pixels_per_m = pixels_per_m;
    return attribute_of(render_svg(arena, {}, options), "class=\"tape\"", "stroke-width");
  };
  EXPECT_EQ(stroke_at(200), 6.0);  // 3 cm at 200 px/m
  EXPECT_EQ(stroke_at(400), 12.0);
  EXPECT_EQ(stroke_at(20), 2.0);
}

TEST(Svg, TextIsAtLeastElevenPixelsAndHasAHalo) {
  const Arena arena = default_warehouse_arena();
  const std::string svg = render_svg(arena, example_run(arena), example_options());
  const std::regex size_re("font-size=\"([0-9.]+)\"");
  int sizes = 0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), size_re);
       it != std::sregex_iterator(); ++it) {
    EXPECT_GE(std::stod((*it)[1]), 11.0);
    ++sizes;
  }
  EXPECT_GT(sizes, 0);
  EXPECT_NE(svg.find(".halo{paint-order:stroke;stroke:#ffffff"), std::string::npos);
  EXPECT_EQ(count(svg, "class=\"mark-label halo\""), 5u);
  EXPECT_EQ(count(svg, "class=\"tag-label halo\""), 2u);
}

TEST(Svg, LabelsOfCrowdedMarksDoNotSitOnTopOfEachOther) {
  Arena arena;
  Trajectory t;
  t.vehicle = "car";
  for (int i = 0; i < 4; ++i) {
    t.marks.push_back({milliseconds(100 * i), {2.0, 1.5}, MarkKind::note, "event"});
  }
  const std::vector<Trajectory> runs{t};
  const std::string svg = render_svg(arena, runs);
  const std::regex label_re("class=\"mark-label[^\"]*\" x=\"([0-9.]+)\" y=\"([0-9.]+)\"");
  std::vector<std::pair<std::string, std::string>> positions;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), label_re);
       it != std::sregex_iterator(); ++it) {
    positions.emplace_back((*it)[1], (*it)[2]);
  }
  ASSERT_EQ(positions.size(), 4u);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    for (std::size_t k = i + 1; k < positions.size(); ++k)
      EXPECT_NE(positions[i], positions[k]);
  }
}

TEST(Svg, NonPositiveScaleIsAProgrammingError) {
  SvgOptions options;
  options.pixels_per_m = 0;
  EXPECT_THROW(render_svg(default_warehouse_arena(), {}, options), std::invalid_argument);
}

TEST(Svg, ExampleWarehouseRun) {
  const Arena arena = default_warehouse_arena();
  const auto runs = example_run(arena);
  // The example is what the docs show: it must start at the start pose and end
  // at station 002.
  EXPECT_EQ(runs[0].samples.front().pose, arena.start);
  EXPECT_LT(length(runs[0].samples.back().pose.position() - Vec2{2.0, 2.4}), 0.01);
  const std::string svg = render_svg(arena, runs, example_options());
  EXPECT_EQ(tag_balance_problem(svg), "");

  if (const char* dir = std::getenv("HIL_WRITE_IMAGES"); dir != nullptr && *dir != '\0') {
    const std::string path = std::string(dir) + "/warehouse.svg";
    std::ofstream file(path, std::ios::binary);
    file << svg;
    ASSERT_TRUE(file.good()) << "could not write " << path;
  }
}

}  // namespace
}  // namespace hil::sim
