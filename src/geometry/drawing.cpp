#include "geometry/drawing.hpp"

#include <algorithm>
#include <limits>

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
  }
  return lo.x <= hi.x;
}

}  // namespace stipplot
