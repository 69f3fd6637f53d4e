#include "drivers/device/pen_rule.hpp"

#include "util/error.hpp"

namespace stipplot {

io::GcodePenRule gcode_pen_rule(const DeviceProfile& p) {
  io::GcodePenRule rule;
  if (p.pen.method == PenMethod::servo) rule.servo_up_s = p.pen.servo_up_s;
  if (p.pen.method == PenMethod::z_axis) {
    if (!(p.pen.z_down_mm < p.pen.z_up_mm))
      throw UserError("profile " + p.name + ": the driver expects z_down_mm below z_up_mm to tell the pen state");
    rule.z_down_below = (p.pen.z_up_mm + p.pen.z_down_mm) / 2;
  } else {
    rule.z_down_below = -1e9;  // Z plays no part in the pen state
  }
  return rule;
}

}  // namespace stipplot
