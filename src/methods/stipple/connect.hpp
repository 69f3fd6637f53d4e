#pragma once
// Connected stippling, TSP art (Kaplan & Bosch 2005): grayscale-order Poisson disk points
// joined by one open travelling-salesman path and drawn with the pen down as one line,
// lifted only where a link would cross light ground.
//
// Tone. A connected drawing's ink is its line: pen width x length. A path through a
// maximal, relaxed Poisson disk pattern of spacing r (kappa / r^2 points per unit area)
// has links of about lambda r, so it lays pen x kappa x lambda / r of ink per unit area:
// the spacing for a tone u is r(u) = kConnectInk x pen / u (kConnectInk = kappa lambda,
// measured), much wider than a dot stipple's, since each point brings a link's ink.
// Dark tones, where lines of neighbouring points overlap, are corrected by a tone
// reproduction curve from a pilot drawing (stipple/tone_law.hpp's CoverageCurve, fitted
// to measured_line_coverage), as the dot stipple's are.
//
// Solid fields. Where the tone asks for solid ink (faded tone >= solid_tone over a field at
// least 2 x solid_open wide), a path is the slowest way to lay it (links of a tenth of a
// millimetre, grbl slowing at every corner) and never quite closes its gaps, which SSIM
// sees in a black field's mean: such fields are hatched instead, parallel lines a pen
// apart linked into zigzags (methods/hatch/hatch_lines.hpp), and their cells get no
// points.
//
// Lifts. A link is not drawn (the pen lifts) when it is longer than `lift_length` local
// spacings (the larger of its ends'), or when the mean tone of the ground it crosses,
// sampled every half cell, is below `lift_tone` x the mean tone of its two ends: its
// line would lay ink on paper that asks for much less. A point whose links are both
// lifted is a single pen touch.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/drawing.hpp"
#include "methods/stipple/stipple.hpp"

namespace stipplot {

// Line length per unit area x spacing of a relaxed maximal Poisson disk pattern joined by
// the planner's tour (kappa lambda above), measured on a uniform grey of 96k points:
// 0.80, and the path's constant c = L / sqrt(N A) = lambda sqrt(kappa) = 1.00, near a
// hexagonal lattice's 1.07 (bench_connect BM_ConnectUniform; the test "a connected
// uniform grey lays ..." checks it on small fields).
inline constexpr double kConnectInk = 0.80;
// At full tone the path lays (1 + kConnectSolid) x the ink of its coverage: the gaps its
// loops leave between neighbouring lines close (the fitted curve asks for at most 1).
inline constexpr double kConnectSolid = 0.6;

struct ConnectParams {
  double fade = 1;             // share of the tone laid (the budget's knob; 1 = all)
  double min_coverage = 0.01;  // fainter tones (after fading) get no points
  const CoverageCurve* curve = nullptr;  // optional: coverage to ask for, per coverage wanted
  int relax = 6;               // Lloyd iterations of the points before the tour
  double lift_length = 3;      // lift links longer than this many local spacings
  double lift_tone = 0.5;      // lift links over ground lighter than this x their ends' tone
  double solid_tone = 0.9;     // faded tones at or above this are hatched solid (> 1: never)
  double solid_open = 0.5;     // mm: fields narrower than twice this stay points (a morphological opening)
  double tour_seconds_cap = 30;  // wall-clock cap of the tour's improvement (work-bounded below it)
  uint64_t seed = 1;
  void validate() const;       // UserError naming the parameter
};

// The spacing in mm for tone u (0..1, before fading) with a pen of `pen_mm`; +infinity
// below min_coverage.
double connect_spacing_mm(double u, double pen_mm, const ConnectParams& p);

// The canvas's exclusion radius per level of its single pass, in grid cells (non-
// decreasing toward lighter levels, as grayscale order needs). O(256).
pds::RadiusTable connect_radii(const StippleCanvas& c, const ConnectParams& p);

struct ConnectStats {
  size_t points = 0;
  size_t links = 0;    // drawn
  size_t lifted = 0;   // links of the path not drawn
  size_t lines = 0;    // polylines
  size_t touches = 0;  // single points
  double length_mm = 0;  // pen-down length of the lines
  size_t solid_cells = 0;  // cells hatched solid
  double hatch_mm = 0;     // their hatch lines' length (in length_mm too)
};

// The cells hatched solid (nonzero), row-major over the canvas's grid. O(cells x the opening's half width).
std::vector<uint8_t> connect_solid_cells(const StippleCanvas& c, const ConnectParams& p);
// The hatch pitch of the solid fields at `fade`, mm.
double connect_solid_pitch_mm(double pen_mm, double fade);

// Would the link a-b (page mm) be lifted: the rule above, on the canvas's single pass.
// O(link length / cell).
bool connect_link_lifted(const StippleCanvas& c, const pds::RadiusTable& radius, const ConnectParams& p, Vec2 a,
                         Vec2 b);

// The method: a pure function of the canvas (one pass: gray, random or negative; throws
// UserError for the others) and the parameters to a Drawing of one layer of polylines
// and pen touches. Time: O(cells) for the order and O(cells x (r_max/g + 2)^2 x
// capacity) for the sampling, O(relax x cells x overlap) for the relaxation, then the
// tour over the N points, O(N k log N) to construct and about O(N) examinations of
// 2-opt/Or-opt (plan/tour.hpp), and O(path length / cell) for the lift rule.
Drawing connect_on_page(const StippleCanvas& c, const ConnectParams& p, ConnectStats* stats = nullptr);

// What a drawing's lines and dots cover of each level of the canvas's single pass:
// rasterised at half a cell, lines as capsules of the pen's width, in bands of rows on
// every thread. O(cells + ink area + marks x bands).
LevelCoverage measured_line_coverage(const StippleCanvas& c, const Drawing& d);

}  // namespace stipplot
