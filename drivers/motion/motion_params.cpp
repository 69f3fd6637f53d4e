#include "drivers/motion/motion_params.hpp"

#include "util/error.hpp"

namespace stipplot {

void validate(const MotionParams& m) {
  require_range("speed_down_mm_s", m.speed_down_mm_s, 1e-3, 1e5);
  require_range("speed_up_mm_s", m.speed_up_mm_s, 1e-3, 1e5);
  require_range("accel_mm_s2", m.accel_mm_s2, 1e-3, 1e7);
  require_range("junction_deviation_mm", m.junction_deviation_mm, 0, 100);
  require_range("pen_change_s", m.pen_change_s, 0, 3600);
  require_range("pen_lift_s", m.pen_lift_s, 0, 60);
  require_range("pen_drop_s", m.pen_drop_s, 0, 60);
  require_range("lookahead_blocks", m.lookahead_blocks, 1, 10000);
}

}  // namespace stipplot
