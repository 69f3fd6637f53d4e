#include "drivers/motion/hpgl_motion.hpp"

#include <algorithm>
#include <cmath>

namespace stipplot::motion {

double start_stop_seconds(double len, double v, double a) {
  if (!(len > 0) || !(v > 0) || !(a > 0)) return 0;
  const double d_ramps = v * v / a;  // accelerate and decelerate
  if (d_ramps <= len) return 2 * v / a + (len - d_ramps) / v;
  return 2 * std::sqrt(len / a);
}

double hpgl_move_seconds(const HpglMotion& m, double dx_units, double dy_units, double v) {
  const double len = std::hypot(dx_units, dy_units) / m.units_per_mm;
  if (!(len > 0)) return 0;
  const double umax = std::max(std::fabs(dx_units), std::fabs(dy_units)) / m.units_per_mm / len;
  return start_stop_seconds(len, v, m.accel_mm_s2 / std::max(umax, 1e-9));
}

}  // namespace stipplot::motion
