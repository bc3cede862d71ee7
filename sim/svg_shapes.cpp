// The small pieces every part of the SVG picture is drawn with: numbers as
// text, text widths, point lists, arrows and the symbols of marks.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>

#include "base/enum_names.hpp"
#include "sim/svg_parts.hpp"

namespace hil::sim::svg_parts {

double Rect::overlap(const Rect& o) const {
  const double w = std::min(x1, o.x1) - std::max(x0, o.x0);
  const double h = std::min(y1, o.y1) - std::max(y0, o.y0);
  return w > 0 && h > 0 ? w * h : 0;
}

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

std::string points_attr(const std::vector<Px>& points) {
  std::string out;
  for (const auto& p : points) {
    if (!out.empty()) out += ' ';
    out += num(p.x) + ',' + num(p.y);
  }
  return out;
}

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

constexpr auto kMarkKindNames =
    base::enum_names<MarkKind>({MarkKind::collision, "collision"}, {MarkKind::stop, "stop"},
                               {MarkKind::station, "station"}, {MarkKind::note, "note"});

std::string_view kind_name(MarkKind kind) {
  return kMarkKindNames.name(kind, "note");
}

std::optional<MarkKind> parse_mark_kind(std::string_view name) {
  return kMarkKindNames.parse(name);
}

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

}  // namespace hil::sim::svg_parts
