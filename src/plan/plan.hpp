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

}  // namespace stipplot
