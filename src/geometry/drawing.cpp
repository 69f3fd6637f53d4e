#include "geometry/drawing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace stipplot {

size_t Drawing::primitive_count() const {
  size_t n = 0;
  for (const auto& l : layers) n += l.primitive_count();
  return n;
}

bool Drawing::bounds(Vec2& lo, Vec2& hi) const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  lo = {inf, inf};
  hi = {-inf, -inf};
  auto grow = [&](Vec2 p, double r) {
    lo.x = std::min(lo.x, p.x - r);
    lo.y = std::min(lo.y, p.y - r);
    hi.x = std::max(hi.x, p.x + r);
    hi.y = std::max(hi.y, p.y + r);
  };
  for (const auto& l : layers) {
    for (const auto& d : l.dots) grow(d.c, d.diameter / 2);
    for (const auto& c : l.circles) grow(c.c, c.r);
    for (const auto& pl : l.lines)
      for (const auto& p : pl.pts) grow(p, 0);
    for (const auto& a : l.areas)
      for (const auto& ring : a.rings)
        for (const auto& p : ring.pts) grow(p, 0);
  }
  return lo.x <= hi.x;
}

Rect Rect::intersect(const Rect& o) const {
  return {std::max(x0, o.x0), std::max(y0, o.y0), std::min(x1, o.x1), std::min(y1, o.y1)};
}

void resolve_pen_numbers(Drawing& d) {
  std::set<int> used;
  for (const auto& l : d.layers)
    if (l.pen.number > 0) used.insert(l.pen.number);
  int next = 1;
  for (auto& l : d.layers) {
    if (l.pen.number > 0) continue;
    while (used.count(next)) ++next;
    l.pen.number = next;
    used.insert(next);
  }
}

double relative_luminance(Color c) {
  auto lin = [](uint8_t v) {
    const double x = v / 255.0;
    return x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4);
  };
  return 0.2126 * lin(c.r) + 0.7152 * lin(c.g) + 0.0722 * lin(c.b);
}

namespace {
bool same_pen(const Pen& a, const Pen& b) {
  return a.name == b.name && a.color == b.color && a.width_mm == b.width_mm && a.number == b.number;
}
template <class T>
void append(std::vector<T>& to, std::vector<T>& from) {
  to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
}
}  // namespace

void merge_layers_by_pen(Drawing& d) {
  std::vector<Layer> merged;
  merged.reserve(d.layers.size());
  for (Layer& l : d.layers) {
    auto it = std::find_if(merged.begin(), merged.end(), [&](const Layer& m) { return same_pen(m.pen, l.pen); });
    if (it == merged.end()) {
      merged.push_back(std::move(l));
      continue;
    }
    append(it->dots, l.dots);
    append(it->lines, l.lines);
    append(it->circles, l.circles);
    append(it->areas, l.areas);
  }
  std::stable_sort(merged.begin(), merged.end(), [](const Layer& a, const Layer& b) {
    return relative_luminance(a.pen.color) > relative_luminance(b.pen.color);
  });
  d.layers = std::move(merged);
}

}  // namespace stipplot
