#pragma once
// Neo-impressionist pointillism with complementary colour contrast (seed 004,
// Sugita & Takahashi; SPEC.md §4).
//  1. Ebauche: Poisson disk sampling of equal circles (radius r), a candidate rejected
//     when d < α_e (r_i + r_j); each circle is filled with the input colour at its
//     centre, on white.
//  2. Regions: Gaussian blur, CIE L*a*b*, L* in [0,100] split uniformly into m levels;
//     a region's colour p_k is the mean (a*, b*) of its pixels.
//  3. Divided strokes: p_i (pure) and p_j (complement) are where the line through the
//     origin and p_k meets a circle about the origin in the a*b* plane, p_i on p_k's
//     side. A second PDS (α_s = 1: circles touch at most) gives N dots in the region;
//     N_pi = W N Dist(p_k,p_j) / (Dist(p_k,p_i) + Dist(p_k,p_j)), N_pj = N - N_pi.
//     Each dot takes L* from the input at its centre.
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/drawing.hpp"
#include "image/image.hpp"
#include "methods/placement.hpp"
#include "eval/lab.hpp"
#include "util/rng.hpp"

namespace stipplot::pointillism {

struct Params {
  double radius_px = 3;        // circle radius r (ebauche and strokes), input pixels
  double alpha_ebauche = 0.5;  // α of the ebauche PDS (< 1: circles overlap)
  double alpha_strokes = 1.0;  // α of the divided-stroke PDS (1: circles never overlap)
  int regions = 16;            // m, uniform L* levels
  double weight = 1.0;         // W in N_pi = W N Dist(pk,pj) / (Dist(pk,pi)+Dist(pk,pj))
  double chroma = 0;           // radius of the a*b* circle; 0 = the gamut-safe chroma per region
  double grey_chroma = 6;      // regions with |p_k| below this get no complement (see .cpp)
  double blur_sigma = 2;       // Gaussian blur before region splitting, pixels
  bool ebauche = true;         // false: divided strokes on white only
  bool strokes = true;         // false: the ebauche alone (Fig. 6b)
  // Dart throwing gives up after this many rejections in a row, as classic PDS does.
  // With α_e = 0.5 the exclusion distance equals r, so where a dart can still land is
  // exactly where no circle covers the canvas: stopping while a few darts in a hundred
  // still land leaves the white ground peeking through, as in the paper's Fig. 6(b)
  // and Seurat's ebauche. 0 = maximal (the canvas fully covered).
  size_t ebauche_misses = 100;
  uint64_t seed = 1;
  void validate() const;       // UserError naming the CLI option
};

// A painted circle in input-pixel coordinates (centre at pixel centre x+0.5, y+0.5).
struct PaintDot {
  float x = 0, y = 0;
  Color color;
  uint16_t region = 0;
  bool complement = false;  // a divided-stroke dot in the complementary colour
};

struct Region {
  size_t pixels = 0;
  double L = 0;              // mean L* of its (blurred) pixels
  lab::Lab mean;             // p_k: (L, mean a*, mean b*)
  double circle = 0;         // radius of the a*b* circle used
  lab::Lab pure, complement; // p_i and p_j (a*, b*; L = the region's mean L*)
  bool grey = false;         // |p_k| < grey_chroma: no complement
  size_t n = 0, n_pure = 0, n_complement = 0;
};

struct Result {
  int width = 0, height = 0;
  double radius_px = 3;
  std::vector<PaintDot> ebauche;  // beneath
  std::vector<PaintDot> strokes;  // above
  std::vector<Region> regions;
  std::vector<uint8_t> labels;    // region of every pixel (row-major)
};

// p_i and p_j on the circle of radius R about the a*b* origin, on the line through
// p_k: p_i = R p_k/|p_k|, p_j = -p_i. |p_k| must be > 0.
void complementary_pair(double a, double b, double R, lab::Lab& pure, lab::Lab& complement);

// The paper's equations (1)-(2), rounded to whole dots: N_pi clamped to [0, N] (W > 1
// can ask for more than N). Returns N_pi.
size_t pure_count(size_t n, const lab::Lab& pk, const lab::Lab& pi, const lab::Lab& pj, double weight);

// Uniformly random permutation of 0..n-1, cache-friendly: scatter into random buckets
// of a few thousand, then Fisher-Yates inside each (each bucket fits in cache). Exactly
// uniform, like a global Fisher-Yates, but without its n cache misses. O(n).
std::vector<uint32_t> random_order(size_t n, Rng& rng);

// Poisson disk sample of equal discs on the pixel grid by dart throwing: pixels visited
// in `order`; a pixel is taken unless a taken one lies at distance < min_dist (the
// paper's strict d < α(r_i + r_j)). Stops after `max_misses` rejections in a row
// (0 = never: a maximal sample). Blocked-pixel map: O(n + dots * min_dist^2) time,
// O(n) bytes.
std::vector<uint32_t> equal_disc_pds(int width, int height, double min_dist, const std::vector<uint32_t>& order,
                                     size_t max_misses = 0);
// The same by brute force (every placed disc checked): O(n * dots). Benchmark baseline
// and test oracle.
std::vector<uint32_t> equal_disc_pds_naive(int width, int height, double min_dist,
                                           const std::vector<uint32_t>& order);

// The method in pixel space. O(n) for blur, Lab, labels and both samplings (n pixels),
// plus O(dots) conversions.
Result paint(const Image& image, const Params& params);
// Builds OpenCV's RGB→Lab tables (once a process, in soft-float: ~60 ms) before paint
// needs them, on a thread of the caller's choosing (the photo decodes meanwhile). O(1).
void prepare_colour_tables();

// On the page. With `pens` empty: exact colours, two layers ("ebauche" beneath,
// "divided strokes" above), every circle filled with its exact colour. With pens: every
// circle's colour mapped to the nearest pen (CIEDE2000), one layer per pen used, named
// as the pen, light pens before dark; within a pen its ebauche circles are pass 0 and its
// strokes' pass 1 (drawn first, then the dots over them); circles filled with the pen
// colour (the planner fills them at the pen width); a circle nearer the paper colour
// than to every pen is not drawn.
// O(dots + distinct colours * pens).
// With pens, `o` may lay the ebauche as hatching per colour field instead: each cell (half a
// pen width) takes the pen of its nearest ebauche circle, then the pen most cells within
// 4 mm take, and each pen's field is filled by parallel lines linked into zig-zags at the
// pen's own angle (hatch_pen_fields, src/methods/hatch/pen_fields.hpp): a few long
// pen-downs where the circles took a pen lift each; lines 0.9 pen widths apart (solid, as
// the circles' fill) over `coverage`. `stroke_share` keeps that share of the divided strokes' circles,
// evenly spread. O(circles r^2 + pens x cells) more.
struct PlaceOptions {
  bool hatch_ebauche = false;
  double coverage = 1;      // (0, 1]
  double stroke_share = 1;  // [0, 1]
};
Drawing place(const Result& r, const Placement& placement, const std::vector<Pen>& pens = {},
              const PlaceOptions& o = {});

Drawing pointillism(const Image& image, const Params& params, const Placement& placement,
                    const std::vector<Pen>& pens = {});

// Fig. 6(c): every pixel painted with its region's colour (region L*, mean a*, b*).
Image region_image(const Result& r);

}  // namespace stipplot::pointillism
