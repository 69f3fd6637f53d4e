#pragma once
// Colour fields laid as hatching, a pen each: the underpainting of a colour drawing
// (pointillism's ebauche, sketch's ground) in continuous ink instead of a pen lift a mark.
// Every cell of a page grid names the pen whose ink it wants (or the paper); the pen most
// cells within `mode_mm` name takes the cell, so neighbours that dither between two pens
// make one field, not a speckle a pen lift each; each pen's field is hatched at its own
// angle.
#include <cstdint>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::hatch {

// A grid of cells over the page: cell (x, y) covers origin_mm + [x, x+1) x cell_mm.
struct PenGrid {
  static constexpr uint8_t kPaper = 255;  // no ink
  int width = 0, height = 0;
  double cell_mm = 0.15;
  Vec2 origin_mm{0, 0};
  std::vector<uint8_t> pen;  // per cell: a pen index below 255, or kPaper
  // Optional, per cell: how much of its pen's ink the cell wants, 0 (paper) .. 1 (the pen's
  // solid colour). Empty: every cell of a field wants one direction of lines.
  std::vector<float> amount;
};

inline constexpr double kFieldModeMm = 4.0;

// The grid with each cell's pen replaced by the one most cells within `mode_mm` name (the
// paper counting as a pen); amounts kept. Independent of the coverage: once per grid.
// O(cells x pens).
PenGrid settle_fields(const PenGrid& grid, size_t n_pens, double mode_mm = kFieldModeMm);

// Appends each pen's fields of a settled grid as lines to layers[k].lines (layers.size() >=
// n_pens, n_pens < 255): parallel lines 0.9 pen widths / coverage apart (coverage in (0,
// 1]), zig-zag linked within a field. With amounts, a cell takes its amount in steps of
// kFieldDirections crossed directions of such lines (n directions of coverage c lay
// 1 - (1 - c)^n), each direction over every cell that wants at least as many, so one line
// crosses many tone steps. O(cells x pens + the lines' length / cell).
inline constexpr int kFieldDirections = 3;
void hatch_fields(const PenGrid& settled, size_t n_pens, double pen_mm, double coverage, std::vector<Layer>& layers);

// settle_fields, then hatch_fields.
void hatch_pen_fields(const PenGrid& grid, size_t n_pens, double pen_mm, double coverage, std::vector<Layer>& layers,
                      double mode_mm = kFieldModeMm);

}  // namespace stipplot::hatch
