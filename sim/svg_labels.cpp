// LabelPlacer: what is drawn is recorded on a grid of cells, and each label
// goes to the spot around its point that covers least of it.

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/text.hpp"
#include "sim/svg_parts.hpp"

namespace hil::sim::svg_parts {

void LabelPlacer::occupy(Rect r, double weight) {
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

void LabelPlacer::occupy_around(Px c, double half_px, double weight) {
  occupy({c.x - half_px, c.y - half_px, c.x + half_px, c.y + half_px}, weight);
}

void LabelPlacer::occupy_line(const std::vector<Px>& points, bool closed, double half_width_px,
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

void LabelPlacer::request(std::string text, Px c, double half_px, std::string_view colour,
                          std::string_view css_class, bool centre_first) {
  requests_.push_back(
      {std::move(text), c, half_px, std::string(colour), std::string(css_class), centre_first});
}

std::string LabelPlacer::place_all() {
  std::string out;
  for (const auto& r : requests_)
    place(r, out);
  return out;
}

long LabelPlacer::cell(double v) {
  return static_cast<long>(std::floor(v / kCellPx));
}

long long LabelPlacer::key(long cx, long cy) {
  return (static_cast<long long>(cx) << 32) ^ static_cast<long long>(cy & 0xffffffffL);
}

double LabelPlacer::covered(const Rect& box) {
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

/// The spots tried for a label, nearest ring first: right, above right,
/// below right, the same on the left, then above and below.
std::vector<LabelPlacer::Candidate> LabelPlacer::candidates(const Request& r) {
  const Px c = r.at;
  std::vector<Candidate> out;
  if (r.centre_first) out.push_back({c.x, c.y + 4, 'm', 0});
  for (int ring = 0; ring < 3; ++ring) {
    const double d = r.half_px + 4 + 18 * ring;
    const double e = d * 0.75;
    out.push_back({c.x + d, c.y + 4, 's', ring});
    out.push_back({c.x + e, c.y - e - 1, 's', ring});
    out.push_back({c.x + e, c.y + e + 10, 's', ring});
    out.push_back({c.x - d, c.y + 4, 'e', ring});
    out.push_back({c.x - e, c.y - e - 1, 'e', ring});
    out.push_back({c.x - e, c.y + e + 10, 'e', ring});
    out.push_back({c.x, c.y - d - 3, 'm', ring});
    out.push_back({c.x, c.y + d + 11, 'm', ring});
  }
  return out;
}

void LabelPlacer::place(const Request& r, std::string& out) {
  const double w = text_width_px(r.text, kLabelFontPx);
  const Px c = r.at;
  const std::vector<Candidate> spots = candidates(r);
  std::size_t best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  Rect best_box;
  for (std::size_t i = 0; i < spots.size(); ++i) {
    const auto& k = spots[i];
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
  const auto& k = spots[best];
  if (k.ring > 0) {
    // From the edge of the thing labelled to the nearest point of the label.
    const Px near{std::clamp(c.x, best_box.x0, best_box.x1),
                  std::clamp(c.y, best_box.y0 + 2, best_box.y1 - 2)};
    const double dx = near.x - c.x, dy = near.y - c.y;
    const double len = std::hypot(dx, dy);
    if (len > r.half_px + 3) {
      const Px from{c.x + dx / len * (r.half_px + 2), c.y + dy / len * (r.half_px + 2)};
      out += "<line class=\"leader\" x1=\"" + num(from.x) + "\" y1=\"" + num(from.y) + "\" x2=\"" +
             num(near.x) + "\" y2=\"" + num(near.y) + "\" stroke=\"" + r.colour +
             "\" stroke-width=\"1\"/>\n";
    }
  }
  const char* anchor = k.anchor == 's' ? "start" : (k.anchor == 'm' ? "middle" : "end");
  out += "<text class=\"" + r.css_class + " halo\" x=\"" + num(k.x) + "\" y=\"" + num(k.baseline) +
         "\" text-anchor=\"" + anchor + "\" fill=\"" + r.colour + "\">" + xml_escape(r.text) +
         "</text>\n";
}

}  // namespace hil::sim::svg_parts
