#pragma once
// Cutting a drawing to a rectangle, so what lies off the paper is never drawn: polylines
// are cut where they cross the edge (a closed one cut once stays one stroke), areas are
// clipped ring by ring (Sutherland-Hodgman, which keeps every point's winding number
// inside a convex window, so holes stay holes under either fill rule), and dots and
// circles wholly outside are dropped; a circle that crosses the edge becomes its clipped
// outline, or a clipped area if it is filled, and a wide dot a clipped area.
#include <cstddef>

#include "geometry/drawing.hpp"

namespace stipplot::layout {

struct ClipCounts {
  size_t cut = 0;      // primitives partly outside, kept in part
  size_t dropped = 0;  // primitives wholly outside
  size_t total() const { return cut + dropped; }
  ClipCounts& operator+=(const ClipCounts& o) {
    cut += o.cut;
    dropped += o.dropped;
    return *this;
  }
};

// O(points of the drawing); circles that cross are flattened within chord_tolerance mm.
ClipCounts clip_to_rect(Drawing& d, const Rect& r, double chord_tolerance = 0.01);

}  // namespace stipplot::layout
