#pragma once
// A profile's machine as the motion models take it: grbl's settings ($100-$132, $11, $1)
// as the profile expects them, or an HPGL plotter's speeds, pens and plotter units.
#include "drivers/device/profile.hpp"
#include "drivers/motion/grbl_motion.hpp"
#include "drivers/motion/hpgl_motion.hpp"

namespace stipplot {

// $110/$111 = speed_up_mm_s, $120/$121 = accel_mm_s2, $11, $100-$102, $112/$122 and $1
// from [grbl] (Z as X without it), the planner size from lookahead_blocks.
motion::GrblSettings grbl_settings_for(const DeviceProfile& p);
motion::HpglMotion hpgl_motion_for(const DeviceProfile& p);

}  // namespace stipplot
