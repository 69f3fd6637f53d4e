#include "geometry/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stipplot {

double chord_angle_step(double r, double tol) {
  if (r <= tol) return std::numbers::pi / 4;
  return std::min(std::numbers::pi / 4, 2 * std::acos(1 - tol / r));
}

std::vector<Vec2> circle_points(Vec2 c, double r, double chord_tolerance, double start_angle) {
  const double two_pi = 2 * std::numbers::pi;
  const int n = std::max(8, static_cast<int>(std::ceil(two_pi / chord_angle_step(r, chord_tolerance))));
  std::vector<Vec2> pts;
  pts.reserve(n + 1);
  for (int k = 0; k <= n; ++k) {
    const double a = start_angle + two_pi * (k == n ? 0 : k) / n;
    pts.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a)});
  }
  return pts;
}

}  // namespace stipplot
