#pragma once
// Hatch fills of areas (filled SVG shapes): parallel pen strokes at a spacing and angle,
// inside the area as its fill rule says (holes stay empty), joined into zigzags where
// consecutive strokes end close together and the connector stays inside. The outline that
// makes the edge crisp is the drawing's own (the SVG reader and the layout's clipping
// give a filled shape its outline as lines).
#include <vector>

#include "geometry/drawing.hpp"
#include "plan/plan.hpp"

namespace stipplot::plan {

struct HatchOptions {
  double spacing_mm = 0.27;   // between hatch lines (the pen width less some overlap fills solid)
  double angle_degrees = 45;  // of the hatch lines, clockwise from the page's x axis
  bool outline = false;       // also draw every ring
};

// A scanline sweep over the rings' edges (rotated so the hatch runs along x), sorted by
// their lowest y, with an active list: O(E log E + L * A + C log C) for E edges, L hatch
// lines, A edges crossing a line and C crossings. Throws UserError when the area would
// need more than 2e7 hatch points (a tiny spacing over a huge area).
std::vector<Stroke> hatch_area(const Area& area, const HatchOptions& opt);

}  // namespace stipplot::plan
