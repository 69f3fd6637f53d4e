#include "drivers/stream/grbl/machine_settings.hpp"

#include <cmath>
#include <cstdio>

namespace stipplot::io::grbl {

SettingsComparison compare_motion_settings(const std::map<int, double>& reported, const motion::GrblSettings& expected) {
  SettingsComparison c;
  c.machine = expected;
  auto take = [&](int key, double& into, double expected_value, const char* unit) {
    const auto it = reported.find(key);
    if (it == reported.end() || !std::isfinite(it->second) || it->second <= 0) return;
    into = it->second;
    if (std::fabs(it->second - expected_value) <= 0.005 * std::fabs(expected_value)) return;
    char b[128];
    std::snprintf(b, sizeof b, "$%d=%g %s (the profile: %g)", key, it->second, unit, expected_value);
    c.time_changes.push_back(b);
  };
  for (int axis = 0; axis < 3; ++axis) {
    take(100 + axis, c.machine.steps_per_mm[axis], expected.steps_per_mm[axis], "steps/mm");
    take(110 + axis, c.machine.max_rate_mm_min[axis], expected.max_rate_mm_min[axis], "mm/min");
    take(120 + axis, c.machine.accel_mm_s2[axis], expected.accel_mm_s2[axis], "mm/s^2");
  }
  take(11, c.machine.junction_deviation_mm, expected.junction_deviation_mm, "mm");
  // $1 in milliseconds; 255 keeps the steppers on (no wait at all).
  const auto lock = reported.find(1);
  if (lock != reported.end() && std::isfinite(lock->second) && lock->second >= 0) {
    const double s = motion::GrblSettings::idle_lock_from_setting(lock->second);
    if (std::fabs(s - expected.idle_lock_s) > 1e-6) {
      char b[128];
      std::snprintf(b, sizeof b, "$1=%g ms (the profile: %g ms)", lock->second, expected.idle_lock_s * 1000);
      c.time_changes.push_back(b);
    }
    c.machine.idle_lock_s = s;
  }
  return c;
}

}  // namespace stipplot::io::grbl
