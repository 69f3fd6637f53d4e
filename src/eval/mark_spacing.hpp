#pragma once
// The spacing of a drawing's marks, as the blur of a tone or colour measure: the scale at
// which the marks merge into a tone. Each mark's spacing is the distance to its nearest
// neighbour; a mark stands for an area of about that spacing squared, so the drawing's
// spacing is their area-weighted mean, sum d^3 / sum d^2 -- the spacing over most of the
// paper, where sqrt(area / marks) would be the spacing of its densest parts.
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot {

// 0 for fewer than two marks (or all at one point). O(n log n).
double mark_spacing(const std::vector<Vec2>& marks);

}  // namespace stipplot
