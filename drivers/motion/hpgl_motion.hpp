#pragma once
// How an HPGL pen plotter moves, as the simulated plotter and the job timer model it:
// every point of a PU/PD list is a start-stop move (these plotters do not blend
// corners), accelerated per axis (each has its own motor), at VS (pen down) or the
// travel speed (pen up); pens go up and down in a fixed time, and a carousel takes a
// fixed time to fetch or stow a pen (SP).
#include "drivers/motion/motion_params.hpp"

namespace stipplot::motion {

struct HpglMotion {
  double speed_down_mm_s = 200;  // until VS says otherwise
  double speed_up_mm_s = 381;
  double accel_mm_s2 = 4000;     // per axis
  double pen_lift_s = 0.05, pen_drop_s = 0.05;
  double pen_change_s = 1.0;     // SP
  double units_per_mm = 40;
};

// The plotter's model from a profile's motion limits. A carousel always takes some time
// to turn: without pen_change_s it gets 1 s.
HpglMotion hpgl_motion_of(const MotionParams& m, double units_per_mm);

// Seconds for a start-stop move of `len` mm at cruise `v` with acceleration `a`. O(1).
double start_stop_seconds(double len, double v, double a);
// A move of (dx, dy) plotter units at cruise `v` mm/s, each axis accelerating at
// m.accel_mm_s2 (so a diagonal accelerates faster along its path). O(1).
double hpgl_move_seconds(const HpglMotion& m, double dx_units, double dy_units, double v);

}  // namespace stipplot::motion
