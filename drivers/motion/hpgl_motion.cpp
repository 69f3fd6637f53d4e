#include "drivers/motion/hpgl_motion.hpp"

#include <algorithm>
#include <cmath>

namespace stipplot::motion {

HpglMotion hpgl_motion_of(const MotionParams& m, double units_per_mm) {
  HpglMotion h;
  h.speed_down_mm_s = m.speed_down_mm_s;
  h.speed_up_mm_s = m.speed_up_mm_s;
  h.accel_mm_s2 = m.accel_mm_s2;
  h.pen_lift_s = m.pen_lift_s;
  h.pen_drop_s = m.pen_drop_s;
  h.pen_change_s = m.pen_change_s > 0 ? m.pen_change_s : 1.0;
  h.units_per_mm = units_per_mm;
  return h;
}

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
