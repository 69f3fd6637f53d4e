#pragma once
// The image as a method works on it: resampled to a grid of square cells of a size on
// paper (tied to the pen), over exactly the image's rectangle on the page. The same page
// and pen give the same grid whatever the input's resolution, so the drawing depends on
// the paper and the pen, not on the file.
#include <cstddef>

#include "geometry/drawing.hpp"
#include "geometry/page.hpp"
#include "image/image.hpp"

namespace stipplot {

struct WorkingGrid {
  Image image;           // RGB, one pixel a cell
  double cell_mm = 0.15; // side of a cell on paper
  Vec2 origin_mm;        // page position of the grid's top-left corner
  // Page position of a point in cell coordinates (cell (i, j) covers [i, i+1] x [j, j+1]).
  Vec2 to_page(double cx, double cy) const { return {origin_mm.x + cx * cell_mm, origin_mm.y + cy * cell_mm}; }
};

// Resamples the image placed by `tf` to cells of about `cell_mm` (area averaging when
// shrinking, bilinear when enlarging). The cell is made larger if the grid would exceed
// `max_cells`, and adjusted so whole cells span the image's width. O(input + cells).
WorkingGrid make_working_grid(const Image& image, const PageTransform& tf, double cell_mm,
                              size_t max_cells = 16'000'000);

}  // namespace stipplot
