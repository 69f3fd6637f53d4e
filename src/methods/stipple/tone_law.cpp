#include "methods/stipple/tone_law.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "util/error.hpp"

namespace stipplot {

namespace {
// C(q) at q = 0, 0.1, ..., 2.0 (see the header).
constexpr double kCoverage[] = {0.000, 0.005, 0.020, 0.046, 0.082, 0.128, 0.184, 0.250, 0.327, 0.413, 0.510,
                                0.610, 0.705, 0.788, 0.856, 0.909, 0.948, 0.974, 0.989, 0.997, 1.000};
constexpr int kSteps = 20;

// Dots per r^2 at r = 1.5, 2, ..., 12 cells, each the mean over r +- 0.1 and +- 0.3 (a
// lattice packs differently at each radius), measured as C.
constexpr double kDensityR[] = {1.5, 2, 2.5, 3, 3.5, 4, 5, 6, 8, 12};
constexpr double kDensity[] = {0.580, 0.573, 0.612, 0.620, 0.615, 0.634, 0.639, 0.649, 0.659, 0.665};
}  // namespace

// Interpolated in sqrt(C), which is linear in q while the dots are apart (C ~ q^2), so
// the spacing of the law's D ~ sqrt(u) dots is exactly even there.
double pattern_coverage(double q) {
  if (!(q > 0)) return 0;
  if (q >= 2) return 1;
  const double x = q * 10;
  const int i = static_cast<int>(x);
  const double f = x - i;
  const double a = std::sqrt(kCoverage[i]), b = std::sqrt(kCoverage[std::min(i + 1, kSteps)]);
  const double s = a + f * (b - a);
  return s * s;
}

double q_for_coverage(double c) {
  if (!(c > 0)) return 0;
  if (c >= 1) return 2;
  int i = 0;
  while (i < kSteps && kCoverage[i + 1] < c) ++i;
  const double lo = std::sqrt(kCoverage[i]), hi = std::sqrt(kCoverage[i + 1]), s = std::sqrt(c);
  return (i + (hi > lo ? (s - lo) / (hi - lo) : 0)) / 10;
}

double pattern_density(double r_cells) {
  constexpr int n = sizeof kDensityR / sizeof kDensityR[0];
  if (r_cells <= kDensityR[0]) return kDensity[0];
  for (int i = 1; i < n; ++i)
    if (r_cells <= kDensityR[i]) {
      const double f = (r_cells - kDensityR[i - 1]) / (kDensityR[i] - kDensityR[i - 1]);
      return kDensity[i - 1] + f * (kDensity[i] - kDensity[i - 1]);
    }
  return kDensity[n - 1];
}

double ToneLaw::dot_mm(double u) const { return std::max(pen_mm, max_dot_mm * std::sqrt(std::clamp(u, 0.0, 1.0))); }

double ToneLaw::spacing_mm(double u) const {
  const double c = fade * std::clamp(u, 0.0, 1.0);
  if (c < min_coverage) return std::numeric_limits<double>::infinity();
  return dot_mm(u) / q_for_coverage(curve ? apply_curve(*curve, c) : c);
}

double apply_curve(const CoverageCurve& curve, double c) {
  if (curve.size() != static_cast<size_t>(kCurvePoints)) return c;
  const double x = std::clamp(c, 0.0, 1.0) * (kCurvePoints - 1);
  const int i = std::min(static_cast<int>(x), kCurvePoints - 2);
  const double f = x - i;
  return curve[static_cast<size_t>(i)] + f * (curve[static_cast<size_t>(i) + 1] - curve[static_cast<size_t>(i)]);
}

CoverageCurve fit_curve(const std::vector<double>& asked, const std::vector<double>& got,
                        const std::vector<double>& weight, const CoverageCurve& before) {
  // Bin the pairs by the coverage asked for, then make "got" non-decreasing in "asked"
  // by pooling adjacent violators (isotonic regression), anchored at (0, 0) and (1, 1).
  constexpr int kBins = 32;
  std::vector<double> sa(kBins, 0), sg(kBins, 0), sw(kBins, 0);
  for (size_t i = 0; i < asked.size(); ++i) {
    if (!(weight[i] > 0)) continue;
    const int b = std::clamp(static_cast<int>(asked[i] * kBins), 0, kBins - 1);
    sa[b] += weight[i] * asked[i], sg[b] += weight[i] * got[i], sw[b] += weight[i];
  }
  struct Block {
    double a, g, w;
  };
  std::vector<Block> pts{{0, 0, 1e9}};
  double total = 0;
  for (int b = 0; b < kBins; ++b) total += sw[b];
  for (int b = 0; b < kBins; ++b)
    if (sw[b] > 1e-4 * total) pts.push_back({sa[b] / sw[b], sg[b] / sw[b], sw[b]});
  pts.push_back({1, 1, 1e9});
  std::vector<Block> pool;
  for (const Block& p : pts) {
    pool.push_back(p);
    while (pool.size() > 1 && pool[pool.size() - 2].g > pool.back().g) {
      Block q = pool.back();
      pool.pop_back();
      Block& r = pool.back();
      const double w = r.w + q.w;
      r = {(r.a * r.w + q.a * q.w) / w, (r.g * r.w + q.g * q.w) / w, w};
    }
  }
  // got(asked) is piecewise linear through the pooled points; invert it at each wanted
  // coverage, then compose with the curve the pilot itself was drawn with.
  CoverageCurve curve(kCurvePoints);
  for (int k = 0; k < kCurvePoints; ++k) {
    const double want = static_cast<double>(k) / (kCurvePoints - 1);
    size_t j = 1;
    while (j + 1 < pool.size() && pool[j].g < want) ++j;
    const Block &lo = pool[j - 1], &hi = pool[j];
    const double f = hi.g > lo.g ? std::clamp((want - lo.g) / (hi.g - lo.g), 0.0, 1.0) : 0.0;
    const double asked_for = lo.a + f * (hi.a - lo.a);
    curve[static_cast<size_t>(k)] = std::clamp(before.empty() ? asked_for : apply_curve(before, asked_for), 0.0, 1.0);
  }
  return curve;
}

void ToneLaw::validate() const {
  require_range("--pen-width", pen_mm, 0.01, 50);
  require_range("--max-dot", max_dot_mm, pen_mm, 100);
  require_range("tone fade", fade, 0, 1);
  require_range("minimum coverage", min_coverage, 0, 1);
}

}  // namespace stipplot
