#pragma once
// What the planner hands to the writers and drivers: per pen, an ordered list of
// strokes. The pen travels up to a stroke's first point, goes down, follows it, and
// lifts. A stroke of one point is a single pen touch (a dot).
// Writers (G-code, HPGL, SVG) and drivers see only this and a device profile, never
// which method made the drawing.
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot {

struct Stroke {
  std::vector<Vec2> pts;  // mm, page coordinates (origin top-left, y down)
};

struct PlannedLayer {
  Pen pen;
  std::vector<Stroke> strokes;  // in plot order
};

struct Plan {
  Page page;
  std::vector<PlannedLayer> layers;  // in plot order; a pen change between layers
};

// A device's motion limits, as the time model needs them (filled from a profile).
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

}  // namespace stipplot
