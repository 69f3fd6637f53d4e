#pragma once
// Sketch strokes of one pen linked into scribbles (issue: continuous ink where the pen
// would otherwise lift). A sketch at an hour's density is thousands of marks a millimetre
// or two long, and on a servo plotter each costs a pen drop and lift (~0.3 s) that would
// draw 10 mm of line: most of the hour goes up and down. Here each pen's strokes are put
// in the planner's own order (plan/tour.hpp: an open path over the strokes' ends, each
// stroke kept whole, drawn either way) and consecutive strokes are joined with the pen
// down where the link runs through ground that wants this pen's ink:
//  - the link is at most `lift_length` local spacings of the pen's marks (the larger of
//    its ends'; a pen with p per cell expects -ln(1 - p) marks a cell, `density` of them
//    kept), and
//  - the pen's probability along it, sampled every half cell, averages at least
//    `lift_tone` x its ends'.
// So a link never crosses ground the pen is not for (white paper, another pen's colour).
#include <cstddef>
#include <cstdint>

#include "geometry/drawing.hpp"
#include "methods/sketch/sketch.hpp"

namespace stipplot::sketch {

struct LinkParams {
  double lift_length = 3;        // lift links longer than this many local spacings
  double lift_tone = 0.5;        // lift links over ground wanting less than this x their ends' ink
  double tour_seconds_cap = 30;  // wall-clock cap of the tour's improvement (work-bounded below it)
  uint64_t seed = 1;
  void validate() const;  // UserError naming the option
};

struct LinkStats {
  size_t strokes = 0;   // strokes in
  size_t lines = 0;     // polylines out (pen drops)
  size_t links = 0;     // links drawn
  double link_mm = 0;   // their length
};

// `kept` is the drawing of r's strokes to plot (to_drawing, perhaps thinned to `density`
// of its marks, 0 < density <= 1); each layer whose pen is one of r's is linked, others
// are copied. Time: per layer the tour's O(n k log n) over its 2n stroke ends, plus
// O(link length / cell) per link; the layers in parallel (the same drawing on any count).
Drawing link_strokes(const SketchResult& r, const Drawing& kept, double density, const LinkParams& p,
                     LinkStats* stats = nullptr);

}  // namespace stipplot::sketch
