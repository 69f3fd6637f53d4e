#pragma once
// Stippling by grayscale-order Poisson disk sampling (seed 000, SPEC.md §1):
// random order, grayscale order, negative, binary, RGB colour (the paper's 27
// colours) and a CMYK ink separation for plotting.
//
// Two ways to size the dots:
//  - the paper's linear law r = a + b d/255 on the image's own pixels (stipple_pixels,
//    stipple), or on the page with a and b as lengths;
//  - on the page for tone (stipple/tone_law.hpp): on a working grid tied to the pen,
//    dots sized and spaced so their ink covers the share of the paper the photo's tone
//    asks for (stipple_on_page with StippleLaw::Tone, the command's default).
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "geometry/drawing.hpp"
#include "image/image.hpp"
#include "methods/placement.hpp"
#include "methods/stipple/pds.hpp"
#include "methods/stipple/tone_law.hpp"
#include "methods/working_grid.hpp"

namespace stipplot {

enum class StippleMethod { Random, Gray, Negative, Binary, Color, Cmyk };

// "random", "gray", ... ; throws UserError for anything else.
StippleMethod parse_stipple_method(const std::string& name);
const char* to_string(StippleMethod m);

struct StippleParams {
  StippleMethod method = StippleMethod::Gray;
  double a = 3, b = 15;                    // r = a + b d/255 (paper: faces 3, 15; thin lines 1, 4)
  double a_b = 3, b_b = 15, a_w = 3, b_w = 15;  // binary: black s = a_b + b_b d/255, white t = a_w + b_w (255-d)/255
  uint64_t seed = 1;
  void validate() const;  // UserError naming the parameter
};

// Dots in pixel (or grid cell) space, one list per output layer, before placement.
struct StippleLayer {
  Pen pen;                      // colour and name of the ink
  std::vector<uint32_t> dots;   // pixel indices y * width + x
  std::vector<double> diameter_mm;  // per dot; empty: the placement's dot size
};
struct StippleResult {
  int width = 0, height = 0;
  Color paper = colors::white;
  std::vector<StippleLayer> layers;
};

// The method proper, in pixel space with the paper's linear law. Time O(n) for ordering
// plus the sampling's O(n * (r_max/g + 2)^2 * c) grid queries (n pixels, g grid cell, c
// cell capacity); colour/CMYK run three or four channels.
// `progress` (optional) receives the fraction done; it never changes the result.
StippleResult stipple_pixels(const Image& image, const StippleParams& params,
                             const std::function<void(double)>& progress = {});

// Pure function from image + parameters to a Drawing: stipple_pixels placed on the page,
// dots at the pixels' centres.
Drawing stipple(const Image& image, const StippleParams& params, const Placement& placement,
                const std::function<void(double)>& progress = {});

// Lays pixel-space dots on the page as pen dots.
Drawing place_stipple(const StippleResult& r, const Placement& placement);

// The CMYK separation stippled by the cmyk method: each ink's coverage as a dark-is-
// dense plane 255 * (1 - coverage), in the order C, M, Y, K. O(pixels).
std::vector<std::vector<uint8_t>> cmyk_separation(const Image& image);

// The process inks the cmyk method's layers are drawn in: cyan, magenta, yellow, black.
std::vector<Pen> cmyk_inks();

// ---- on the page ----

enum class StippleLaw { Tone, Linear };
StippleLaw parse_stipple_law(const std::string& name);  // "tone" | "linear"; UserError otherwise

struct PageStipple {
  StippleLaw law = StippleLaw::Tone;
  // Tone: the largest dot (at full tone) and the share of the tone laid; the pen comes
  // from the placement. See stipple/tone_law.hpp.
  double max_dot_mm = 0.3;
  double fade = 1;
  int relax = 6;  // Lloyd iterations evening the sampled pattern (0: as sampled)
  // Per pass, a tone reproduction curve (empty: none): how a caller corrects the law
  // for a particular photo (grayscale order packs the dots of smooth gradients closer
  // than the uniform patterns the law was measured on, dots shrink beside highlights,
  // dark tones saturate), from a pilot drawing's measured_coverage.
  std::vector<CoverageCurve> pass_curve;
  // Linear: the paper's a, b (and binary's a_b ... b_w) as lengths on paper or in input
  // pixels, all multiplied by `spread` (>= 1: sparser, the budget's way to thin it).
  Length a{3, true}, b{15, true}, a_b{3, true}, b_b{15, true}, a_w{3, true}, b_w{15, true};
  double spread = 1;
  void validate() const;  // UserError naming the option
};

// One pass of dots over one plane of the grid: which plane, and whether its ink darkens
// (dark: level 0 = the most ink), or is binary's black or white ink on grey.
struct StipplePass {
  enum class Ink { Dark, Black, White } ink = Ink::Dark;
  size_t plane = 0;
};

// The image made ready for stippling on the page: the working grid, the planes the
// method stipples (luma, its inverse, R G B, or C M Y K coverage), the passes over them
// and each pass's pen. O(cells).
struct StippleCanvas {
  StippleMethod method = StippleMethod::Gray;
  WorkingGrid grid;
  Page page;  // the page, in the paper's colour
  std::vector<std::vector<uint8_t>> planes;
  std::vector<StipplePass> passes;
  std::vector<Pen> pens;  // one a pass (colour keeps its own 26 pens, see stipple_on_page)
  double pen_mm = 0.3;
  double dot_mm = 0.3;    // the linear law's drawn dot (the placement's --dot-size, or the pen)
};
StippleCanvas prepare_stipple(const Image& image, StippleMethod method, const Placement& placement,
                              double cell_mm);

// The share of the paper a pass's ink should cover at a level of its plane (0..1).
double pass_tone(StipplePass::Ink ink, int level);

// Each level's dot in pass `pass` of the canvas: exclusion radius in grid cells (+inf:
// no dot) and drawn diameter in mm.
struct LevelDots {
  pds::RadiusTable radius;
  std::array<double, 256> diameter_mm{};
};
LevelDots level_dots(const StippleCanvas& c, size_t pass, const PageStipple& law, double mm_per_px);

// Stipples the canvas (grayscale order everywhere but Random) and places the dots on the
// page, each jittered uniformly within its cell so positions are continuous; with the
// tone law then relaxed toward weighted Voronoi centroids (law.relax times, see
// stipple.cpp's relax: O(cells x overlap) each), and no dot
// wider than the pen reaching past the image's rectangle. With the
// tone law a dot's diameter follows the mean tone under it, not only at its centre, so
// a dark dot beside a highlight shrinks instead of covering it, and a highlight smaller
// than a dot gets a dot its size. O(cells * (r_max/g + 2)^2 * capacity + dots * D^2)
// per pass (D the dot diameter in cells).
Drawing stipple_on_page(const StippleCanvas& canvas, const PageStipple& law, double mm_per_px, uint64_t seed,
                        const std::function<void(double)>& progress = {});

// Lloyd relaxation of points in cell coordinates over a plane of the grid (Secord's
// weighted Voronoi stippling): each point moves to the centroid of the cells nearest to
// it, weighted by the density the radius table asks for there (1/r^4, so a centroidal
// pattern keeps the sampled density 1/r^2), `iterations` times; a point claims the cells
// within 1.5 of its own spacing, and cells of levels that get no points weigh nothing.
// O(iterations x cells x overlap).
// The nearest dots in parallel over bands of rows, the centroids in one pass over the
// cells; the same bit for bit on any thread count.
void relax_points(std::vector<Vec2>& pts, const std::vector<uint8_t>& plane, const pds::RadiusTable& radius, int w,
                  int h, int iterations);

// What a drawing of the canvas (one layer a pass, as stipple_on_page makes) covers: per
// pass and grey level of its plane, the share of those cells its dots' discs cover,
// rasterised at half a cell; and how many cells each level has. O(cells + dots D^2).
struct LevelCoverage {
  std::array<double, 256> covered{}, cells{};
};
std::vector<LevelCoverage> measured_coverage(const StippleCanvas& canvas, const Drawing& drawing);

}  // namespace stipplot
