#pragma once
// Dendritic drawings (seed 002, SPEC.md §3): grayscale-order Poisson disk stipples
// joined by a minimum spanning tree under an anisotropic distance, drawn as pen
// strokes; and terrain maps shaded from the tree's distance transform.
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/drawing.hpp"
#include "image/image.hpp"
#include "methods/placement.hpp"
#include "methods/tree/edges.hpp"
#include "methods/tree/mst.hpp"

namespace stipplot::tree {

// What --distance names: the cost of each tree drawn (one layer each), and whether the
// major edges join the points and their distance transform replaces the image (cross).
struct Variant {
  std::string name;
  bool cross = false;
  std::vector<Distance> layers;
};
// ed, bd, sibd, bd+sibd; ced, cbd, csibd, cbd+csibd (cross). UserError otherwise.
Variant parse_variant(const std::string& name);

struct TreeParams {
  Variant variant = parse_variant("sibd");
  double a = 2, b = 8;      // stipple radius r = a + b d/255 (paper: 2, 8)
  // The tone law instead (--law tone): r = a / t with t = 1 - d/255 the darkness, up to
  // a + b, so the lines' ink follows the tone; lighter ground gets no point, and an edge
  // longer than kBridge times its ends' radius (one that bridges such ground) is not drawn.
  bool tone_law = false;
  double alpha_bd = 1;      // BD / CBD intensity weight
  double alpha_sibd = 0.5;  // SIBD / CSIBD penalty weight
  double h = 300;           // SIBD threshold
  double sigma = 1.5;       // Gaussian blur of the input giving BD's d (px); 0 = none
  double dt_gain = 0;       // cross: d = gain * edge distance (grey levels / px); 0 = scale to 0..255
  EdgeParams edges;
  bool reference_prim = false;  // use the paper's O(n²) Prim (slow; for comparison)
  uint64_t seed = 1;
  void validate() const;  // UserError naming the option
};

inline constexpr double kBridge = 3;

struct TreeLayer {
  Distance kind;
  std::vector<Edge> edges;
  size_t bridges = 0;       // tone law: edges left out as bridges over light ground
  double mean_abs_cos = 0;  // mean |cos| between edges and the local gradient of d
  size_t measured = 0;      // edges where the gradient was large enough to measure
};

struct TreeResult {
  int width = 0, height = 0;
  bool cross = false;
  PointSet points;                 // stipples, then (cross) edge pixels
  size_t stipple_count = 0;
  std::vector<uint8_t> grey;       // input luma
  std::vector<float> field;        // d per pixel: blurred luma, or scaled edge distance (cross)
  std::vector<uint8_t> edge_mask;  // cross: 255 on major edges
  std::vector<float> edge_dt;      // cross: distance (px) to the nearest major edge
  std::vector<TreeLayer> layers;
  double seconds_points = 0, seconds_edges = 0, seconds_mst = 0;
};

// The method in pixel space. Time: O(n) stippling, O(n r²) edges (cross), and per
// tree mst_exact's O(m log m)-like Borůvka over m points (or O(m²) with reference_prim).
TreeResult tree_pixels(const Image& image, const TreeParams& params);

// Tree segments as 2-point polylines, one pen layer per tree. Where so many segments meet
// that their ink would fill the disc of kCrowdDiscMm around the point (a blot on paper),
// each stops short of it by the gap that keeps the disc's coverage at kCrowdCoverage
// (crowd_gap_mm), never by more than kCrowdMaxShare of its length: the lines keep their
// directions, so the tree keeps its shape. O(points + edges).
//
// With `strokes.link`, the segments of each tree are drawn as trails instead
// (forest_trails, trails.hpp): a segment that stops short of a crowded point ends its
// trail there, and an edge is drawn back along, pen down, where that is shorter than
// `strokes.retrace_mm` (the line as long as a pen lift takes; 0 = never), so a tree of
// thousands of edges is tens of strokes, not thousands of pen lifts. O((points + edges)).
inline constexpr double kCrowdDiscMm = 1.0;
inline constexpr double kCrowdCoverage = 0.75;
inline constexpr double kCrowdMaxShare = 0.4;
//
// With `strokes.weight` over 1 (pen widths), each tree is drawn as one closed loop round
// it instead (forest_outlines, trails.hpp), (weight - 1) / 2 pen widths to either side of
// its edges: at weight 2 a line two pens wide, no pen lift inside a tree and no ink laid
// twice; the crowded points' gaps do not apply (the loop passes round every point).
struct TreeStrokes {
  bool link = false;
  double retrace_mm = 0;
  double weight = 1;
};
Drawing place_tree(const TreeResult& r, const Placement& placement, const TreeStrokes& strokes = {});

// The gap from a point at which `lines` pen lines of `pen_mm` ending there must stop so
// their ink covers at most `coverage` of a disc of diameter `disc_mm` around it (each line
// lays pen x (radius - gap) in it): 0 when they already do.
double crowd_gap_mm(size_t lines, double pen_mm, double disc_mm = kCrowdDiscMm, double coverage = kCrowdCoverage);

// Pure function from image + parameters to a Drawing.
Drawing tree_drawing(const Image& image, const TreeParams& params, const Placement& placement, const TreeStrokes& strokes = {});

// Mean |cos| between tree edges and the gradient of `field` (Sobel) at each edge's
// midpoint, over edges where the gradient exceeds min_gradient. O(edges).
double mean_abs_cos_to_gradient(const PointSet& pts, const std::vector<Edge>& edges, const std::vector<float>& field,
                                int width, int height, double min_gradient, size_t* measured = nullptr);

struct TerrainParams {
  double valley_depth = 6;  // height added per pixel of distance from the tree (grey levels / px)
  double relief = 1.5;      // bump-mapping strength
  double azimuth = 315;     // light direction, degrees clockwise from up (315 = top left)
  double elevation = 45;    // light height above the horizon, degrees
  void validate() const;    // UserError naming the option
};

// Terrain map (image size): height = input (or edge distance, cross) + valley_depth ·
// distance from the rasterised trees; coloured green (low) to red (high), major
// edges blue, shaded by bump mapping under the light. O(n).
Image terrain(const TreeResult& r, const TerrainParams& params);

}  // namespace stipplot::tree
