#include "geometry/drawing.hpp"

#include <algorithm>
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

}  // namespace stipplot
