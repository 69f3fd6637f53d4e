#pragma once
// Stippling for tone on paper: how big and how far apart dots must be for the ink to
// cover a given share of the paper. A maximal Poisson disk pattern of spacing r (no two
// dots closer than r, no room left for another) holds kappa / r^2 dots per unit area
// and, with dots of diameter D, covers C(D / r) of the paper: C rises as 0.534 q^2 while
// the dots are apart (q <= 1) and reaches 1 at q = 2 (a maximal pattern leaves no point
// farther than r from a dot, and the dots' radius is then r).
//
// The law (after StippleGen's dot size by darkness): a dot is one pen touch in light
// tones and grows with the square root of the tone above that, D(u) = max(pen,
// D_max sqrt(u)); the spacing follows from C: r(u) = D(u) / C^-1(fade * u). With
// D ~ sqrt(u) the spacing is even where dots are larger than the pen (only their size
// follows the tone) and grows in light tones, and it never shrinks as the tone lightens,
// which is the order grayscale-order stippling visits the pixels in. `fade` < 1 lays an
// even share of the tone when the time budget cannot lay it all.
#include <cstdint>
#include <vector>

namespace stipplot {

// C(q): covered share of the paper by dots of diameter q r in a maximal pattern of
// spacing r, measured on pds::sample of a uniform grey (grayscale order: random among
// equals) averaged over r = 4.6 ... 10.7 cells, centres jittered within their cell
// (tests/stipple/test_tone_law.cpp measures it again). Monotone.
double pattern_coverage(double q);
// Its inverse on [0, 1]: the smallest q with C(q) >= c (2 for c >= 1).
double q_for_coverage(double c);
// Dots per r^2 of a maximal pattern on a grid, for a spacing of `r_cells` grid cells
// (the grid's granularity packs fewer below about 4 cells). Measured as C.
double pattern_density(double r_cells);

// A tone reproduction curve: the coverage to ask the law for, so that a drawing of a
// particular photo gets a wanted coverage (measured by a pilot drawing, see
// stipple.hpp's measured_coverage). kCurvePoints samples over 0..1; empty = as wanted.
inline constexpr int kCurvePoints = 65;
using CoverageCurve = std::vector<double>;
double apply_curve(const CoverageCurve& curve, double c);
// From (asked, got) coverage pairs with weights: the curve asking for what gets the
// wanted coverage, through the monotone fit of got against asked.
CoverageCurve fit_curve(const std::vector<double>& asked, const std::vector<double>& got,
                        const std::vector<double>& weight, const CoverageCurve& before = {});

struct ToneLaw {
  double pen_mm = 0.3;      // a touch's diameter, the smallest dot
  double max_dot_mm = 0.3;  // D at full tone
  double fade = 1;          // share of the tone laid (the budget's, 1 = all)
  double min_coverage = 0.004;  // below this a tone gets no dots
  const CoverageCurve* curve = nullptr;  // optional correction of the coverage asked for

  // u: the tone (share of the paper to cover, 0..1) before fading.
  double dot_mm(double u) const;
  // Spacing r in mm; +infinity where the faded tone is below min_coverage.
  double spacing_mm(double u) const;
  void validate() const;  // UserError naming the option
};

}  // namespace stipplot
