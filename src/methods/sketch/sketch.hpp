#pragma once
// Colour sketches with real pens by point redistribution (seed 001, SPEC.md §2):
// per pen a probability p(x) per cell, Secord's redistribution places that pen's points,
// and each point becomes a short stroke along the local edge (longer and thicker where
// the gradient is strong, a plain short hatch mark where the image is flat).
//
// Pen probability models:
//  - rgb: the paper's 8 pens (R, G, B, Y, M, C, black, grey 0.5); p = max(0, (d - D)/d)
//    with D the Euclidean RGB distance (channels in [0, 1]), d = sqrt(3)/2, grey d = 0.15.
//  - hsi: the paper's 6 hue pens at 0, pi/3, ... plus black; p = max(0, (r - |dtheta|)/r),
//    r = pi/3, circular hue difference (0 for grey pixels, whose hue is undefined);
//    black p = exp(-5 s), s the HSI saturation.
//  - pens (a user palette): the RGB distance model, which works for any pen colours. Each
//    pen's reach d is the distance to its nearest other pen, capped at sqrt(3)/2 (this
//    gives the paper's d for R, G, B, Y, M, C), or --reach for all pens.
// (--hsi-black chroma: see HsiBlack.)
// Lightening (where the pixel is brighter than the pen, t = (Y_pixel - Y_pen)/(1 - Y_pen)
// in Rec. 601 luma): the paper's preview draws the mark lightened toward white by t; ink
// cannot be lightened, so for plotting the pen's marks are thinned so that its ink covers
// (1 - t) of what it would (keep share k = ln(1 - (1-t) p) / ln(1 - p): 1 - t where
// marks are sparse, fewer where they overlap).
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/drawing.hpp"
#include "image/image.hpp"
#include "methods/hatch/pen_fields.hpp"
#include "methods/placement.hpp"

namespace stipplot::sketch {

enum class ColorSpace { Rgb, Hsi, Pens };
ColorSpace parse_color_space(const std::string& name);  // "rgb" | "hsi"; UserError otherwise
const char* to_string(ColorSpace s);

enum class Lighten { Auto, On, Off };  // auto: on for hsi (as the paper), off otherwise

// The HSI black pen: the paper's exp(-5 s) with the HSI saturation s (which is large for
// dark, slightly tinted pixels, so black goes missing there, as the paper reports), or
// an extension: exp(-5 c) with the chroma c = max - min of R, G, B (small for every
// dark pixel), and the hue pens scaled by (1 - p_black) so they give way to it.
enum class HsiBlack { Paper, Chroma };
HsiBlack parse_hsi_black(const std::string& name);
Lighten parse_lighten(const std::string& name);

struct SketchParams {
  ColorSpace space = ColorSpace::Rgb;
  std::vector<Pen> pens;          // the user palette (space = Pens); widths in mm
  double reach = 0;               // pens: RGB reach d for every pen; 0 = automatic
  Length cell{0, false};          // sampling grid cell: mm on paper or input px ("3px"); 0 = auto_cell_mm()
  double mark_mm = 1.2;           // stroke length where the image is flat
  double edge_mm = 3.5;           // stroke length at strong edges
  double edge_low = 0.04;         // gradient (luma change per cell, 0..1) where strokes start to follow edges
  double edge_high = 0.20;        // gradient at which strokes are longest and thickest
  int max_passes = 3;             // parallel passes of a stroke at the strongest edges
  double hatch_deg = 45;          // direction of flat marks, degrees counter-clockwise from +x
  Lighten lighten = Lighten::Auto;
  HsiBlack hsi_black = HsiBlack::Paper;
  // How points are drawn from q: the R2 low-discrepancy sequence (Secord's way) or
  // independent random draws (for comparison; also the benchmark's baseline).
  enum class Sampler { LowDiscrepancy, Random } sampler = Sampler::LowDiscrepancy;
  uint64_t seed = 1;
  void validate() const;  // UserError naming the option
  // The default cell: sqrt(mark length x mean pen width), so one flat mark's ink covers
  // one cell's area; then a pen expecting -ln(1 - p) marks per cell (Secord's m q for
  // large m) covers 1 - exp(-(-ln(1 - p))) = p of the paper if marks fall independently.
  double auto_cell_mm(const std::vector<Pen>& pens) const;
  bool lighten_on() const { return lighten == Lighten::On || (lighten == Lighten::Auto && space == ColorSpace::Hsi); }
};

// The built-in pens of a mode, with their reach d (rgb) or hue (hsi); pen width from `width_mm`.
std::vector<Pen> builtin_pens(ColorSpace s, double width_mm);

struct Stroke {
  Polyline line;          // page mm; a zigzag of `passes` parallel passes
  float lighten = 0;      // 0 = the pen's colour, 1 = white (paper preview)
  bool plotted = true;    // false: thinned out of the plot because of lightening
};

struct PenStrokes {
  Pen pen;
  double m = 0;           // solved point count for this pen
  bool degenerate = false;
  std::vector<Stroke> strokes;
};

struct SketchResult {
  Page page;
  int grid_w = 0, grid_h = 0;   // the sampling grid
  double cell_mm = 0;
  std::vector<PenStrokes> pens;
  // Each pen's probability p per grid cell (as pens), and where the grid lies on the page:
  // cell (x, y) covers grid_origin_mm + [x, x+1) x cell_w_mm, [y, y+1) x cell_h_mm.
  std::vector<std::vector<float>> prob;
  Vec2 grid_origin_mm{0, 0};
  double cell_w_mm = 0, cell_h_mm = 0;
  size_t plotted_strokes() const;
};

// The method proper. Time O(N + n k + M): N input pixels (one area resize), n grid cells
// (probabilities, structure tensor, k Newton steps per pen, guide tables), M strokes.
SketchResult sketch_strokes(const Image& image, const SketchParams& params, const Placement& placement);

// The Drawing to plot: one layer per pen with its plotted strokes (empty pens dropped),
// light pens before dark (merge_layers_by_pen).
Drawing to_drawing(const SketchResult& r);

// The ground under the strokes (sketch --ground hatch): the photo's colour fields laid as
// hatching, a pen each, as pointillism lays its ebauche, so the hour's ink reaches the
// photo's tone where scattered strokes leave the page light. Each cell of half a pen width
// over the image's rectangle takes the pen nearest (CIEDE2000) the photo's colour there,
// the paper counting as a pen (no ink); the fields settled (hatch::settle_fields) once, as
// they do not depend on the budget. O(input pixels + cells x pens).
hatch::PenGrid ground_grid(const Image& image, const std::vector<Pen>& pens, const Placement& placement);
// The fields hatched at `coverage` (0, 1] (hatch::hatch_fields), a layer per pen that has
// one, named as the pen. O(cells x pens + the lines).
Drawing ground_drawing(const hatch::PenGrid& grid, const std::vector<Pen>& pens, const Placement& placement,
                       double coverage);

// Pure function image + parameters -> Drawing.
Drawing sketch(const Image& image, const SketchParams& params, const Placement& placement);

// Per-cell probabilities of each pen for an image already at grid resolution (exposed
// for tests). p[c][y*w + x].
std::vector<std::vector<float>> pen_probabilities(const Image& grid, const SketchParams& params,
                                                  const std::vector<Pen>& pens);

// Edge direction field: unit tangent (along the edge, across the gradient) and strength
// (gradient magnitude of the luma in [0, 1] per cell) from the smoothed structure tensor.
struct EdgeField {
  int w = 0, h = 0;
  std::vector<float> tx, ty, strength;
};
EdgeField edge_field(const Image& grid);

enum class PreviewStyle { Paper, Plot };
PreviewStyle parse_preview_style(const std::string& name);

// The sketch preview: strokes rasterised at `dpi`; where strokes of different pens
// overlap the pixel shows the average of their colours (the paper's rule), blended over
// the paper by coverage. Paper style draws every stroke lightened by its factor; plot
// style draws what the plotter will, in full pen colours. O(M * stroke area + pixels).
Image render_sketch_preview(const SketchResult& r, double dpi, PreviewStyle style);

}  // namespace stipplot::sketch
