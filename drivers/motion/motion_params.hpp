#pragma once
// A machine's motion limits: what the time model needs to know about a plotter, read
// from the [motion] section of its device profile (and what the simulators move by).
namespace stipplot {

struct MotionParams {
  double speed_down_mm_s = 50;   // max feed with the pen down
  double speed_up_mm_s = 150;    // max feed travelling with the pen up
  double accel_mm_s2 = 1000;     // per-axis acceleration limit, grbl-style
  double junction_deviation_mm = 0.01;
  double pen_lift_s = 0.15;      // time for the pen to go up
  double pen_drop_s = 0.15;      // time for the pen to come down
  int lookahead_blocks = 15;     // planner buffer (grbl: 15 blocks on a 328p)
  // Machine time to take up a pen (an HPGL carousel's SP), charged for every pen
  // selected and for putting the last one away; 0 where a person changes pens (M0).
  double pen_change_s = 0;
};

// Checks the parameters (UserError naming the one that is wrong).
void validate(const MotionParams& m);

}  // namespace stipplot
