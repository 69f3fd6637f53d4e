#pragma once
// Parallel hatch lines clipped to a region of a grid, consecutive lines linked into
// zig-zag strokes where the link is short and stays inside the region (up to a cell: a
// region's edge on a grid is a staircase whose corners a straight link along it clips),
// so the pen draws a region's lines in few pen-downs. Pure geometry in cell coordinates.
#include <cstdint>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::hatch {

// A region of a grid of square cells (row-major, nonzero = inside); cell (i, j) covers
// [i, i+1] x [j, j+1].
struct Mask {
  int width = 0, height = 0;
  std::vector<uint8_t> in;
  bool inside(double cx, double cy) const;  // false off the grid
};

struct LineSet {
  double angle_deg = 45;  // direction, counter-clockwise from +x as seen on the page (y down)
  double spacing = 4;     // between lines, cells
  double link = 10;       // longest zig-zag link, cells
};

// The region's lines as strokes (cell coordinates). Lines lie at multiples of the spacing
// (plus half) from the grid's origin, so two sets at one angle and spacing coincide.
// Each line is sampled every half cell: O(D^2 / spacing) samples for a grid of diagonal D,
// plus O(runs log runs) to link them.
std::vector<std::vector<Vec2>> hatch_mask(const Mask& mask, const LineSet& set);

}  // namespace stipplot::hatch
