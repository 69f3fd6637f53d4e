#pragma once
// Tone hatching, in the manner of vpype's `hatched`: the photo's grey, blurred on paper,
// split into a few tone bands; band b of N is drawn with b crossed directions of parallel
// lines (45°, 135°, 0°, 90°, ...), each direction over every band at least as dark as its
// own, so one long pen-down line crosses many bands. Each direction's spacing is chosen
// so the lines' ink lays the band's mean darkness (crossed lines of coverage c1, c2 darken
// 1 - (1 - c1)(1 - c2)); the budget's knob widens every spacing alike.
#include <string>
#include <vector>

#include "geometry/drawing.hpp"
#include "image/image.hpp"
#include "methods/placement.hpp"

namespace stipplot::hatch {

inline constexpr int kMaxLevels = 9;  // eight directions: 45° apart, then 22.5°

struct HatchParams {
  int levels = 5;             // tone bands, white (no ink) included
  double spacing_mm = 0;      // closest lines of one direction; 0: the pen's width
  double spacing_scale = 1;   // the budget's knob: every spacing times this (>= 1)
  double blur_mm = 0.8;       // Gaussian sigma of the grey on paper
  double angle_deg = 45;      // the first direction, counter-clockwise from +x
  double link_mm = 3;         // longest zig-zag link (one across to the next line always allowed)
  bool contours = false;      // also trace each band's boundary
  std::vector<Pen> pens;      // light to dark over the directions; empty: one black pen
  void validate() const;      // UserError naming the option
};

// The photo's tone on paper: its grey on a grid of cells over the image's rectangle.
struct ToneMap {
  int width = 0, height = 0;
  double cell_mm = 0.3;
  Vec2 origin_mm;                  // page position of the grid's top-left corner
  std::vector<uint8_t> band;       // per cell: 0 (lightest, no ink) .. levels - 1
  std::vector<double> area_mm2;    // per band
  std::vector<double> darkness;    // per band: mean darkness (0 white .. 1 black) of its cells
};
// O(cells + input pixels).
ToneMap tone_map(const Image& image, const HatchParams& p, const Placement& placement);

// Direction j (0-based) hatches bands j + 1 and darker.
struct Direction {
  double angle_deg = 45;
  double spacing_mm = 0;  // at knob scale 1; 0: not drawn (the band needs no more ink)
  Pen pen;
  double pen_darkness = 1;  // 1 - the pen colour's luma
};
// Spacings from the bands' darkness, each no closer than the pen width and --spacing.
std::vector<Direction> directions(const ToneMap& t, const HatchParams& p, double pen_width_mm);

// The darkness band b reaches with the directions at spacing x scale.
double band_darkness(const std::vector<Direction>& dirs, size_t band, double scale);
// The photo's own mean darkness (blurred) over the image's rectangle.
double photo_darkness(const ToneMap& t);
// Mean darkness the lines lay over the image's rectangle at spacing x scale.
double mean_darkness(const ToneMap& t, const std::vector<Direction>& dirs, double scale);

// The lines (and contours) at spacing x p.spacing_scale, one layer a direction, on a
// page of `page`. O(D^2 / spacing) per direction for a grid of diagonal D cells.
Drawing hatch_lines(const ToneMap& t, const std::vector<Direction>& dirs, const HatchParams& p, const Page& page);

// Pure function from image + parameters to a Drawing. O(input + cells + L D^2 / s) for L
// directions over a grid of diagonal D cells at spacing s (cells), plus the contours'
// O(cells) per band.
Drawing hatch_drawing(const Image& image, const HatchParams& p, const Placement& placement);

}  // namespace stipplot::hatch
