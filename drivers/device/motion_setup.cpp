#include "drivers/device/motion_setup.hpp"

namespace stipplot {

motion::GrblSettings grbl_settings_for(const DeviceProfile& p) {
  motion::GrblSettings s;
  const MotionParams& m = p.motion;
  const GrblSetup& g = p.grbl;
  s.steps_per_mm = {g.steps_per_mm_x, g.steps_per_mm_y, g.steps_per_mm_z};
  const double z_rate = g.max_rate_z_mm_s > 0 ? g.max_rate_z_mm_s : m.speed_up_mm_s;
  s.max_rate_mm_min = {m.speed_up_mm_s * 60, m.speed_up_mm_s * 60, z_rate * 60};
  const double z_accel = g.accel_z_mm_s2 > 0 ? g.accel_z_mm_s2 : m.accel_mm_s2;
  s.accel_mm_s2 = {m.accel_mm_s2, m.accel_mm_s2, z_accel};
  s.junction_deviation_mm = m.junction_deviation_mm;
  s.idle_lock_s = motion::GrblSettings::idle_lock_from_setting(g.idle_lock_ms);
  s.planner_blocks = m.lookahead_blocks;
  return s;
}

motion::HpglMotion hpgl_motion_for(const DeviceProfile& p) {
  return motion::hpgl_motion_of(p.motion, p.machine.units_per_mm);
}

}  // namespace stipplot
