#pragma once
// Secord et al.'s point redistribution (SPEC.md §2): m points are spread over a grid of
// n cells with density q so that a cell receives at least one point with probability p:
//   p = 1 - (1 - q)^m,  q = 1 - (1 - p)^(1/m),  sum q = 1  <=>  sum (1 - p)^(1/m) = n - 1.
// Points are placed by inverting the 2-D cumulative distribution (rows by the marginal,
// then the column within the row) at the points of a low-discrepancy sequence, so they
// spread evenly instead of clumping as independent draws do.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace stipplot::sketch {

// p is capped at 1 - e^-4: a cell that matches a pen exactly then expects at most about
// four points (m q -> -ln(1 - p) for large m). Without a cap one cell with p = 1 makes the
// equation unsolvable (its term is 0 for every m) and needs infinitely many points.
inline constexpr double kMaxPointsPerCell = 4.0;
double max_probability();  // 1 - exp(-kMaxPointsPerCell)

struct PointCount {
  double m = 0;            // the solution of the equation (real; round it to place points)
  double s = 0;            // 1/m, the exponent used for q (0 when m = 0)
  bool degenerate = false; // fewer than two cells with p > 0: see solve_point_count
  int iterations = 0;
};

// Solves sum (1 - p_i)^(1/m) = n - 1 for m, with p clamped to [0, max_probability()]
// (NaN counts as 0). Written as h(s) = sum (1 - exp(-s a_i)) = 1 with a_i = -ln(1 - p_i)
// and s = 1/m: h is increasing and concave, so Newton's method started below the root
// (s0 = 1 / sum a_i) climbs to it monotonically without overshooting.
// Degenerate cases, where the equation has no finite positive solution:
//  - every p = 0: m = 0, no points;
//  - exactly one cell with p > 0 (including 1-cell images): h(s) < 1 for all s, so we
//    take m = a_i = -ln(1 - p_i), the expected count the general case tends to.
// Time O(n * k) with k Newton steps (k <= 100; about 4-8 in practice), memory O(n).
PointCount solve_point_count(const std::vector<float>& p);

// The naive solver, kept as the benchmark baseline: bisection on s to full precision
// (about 60 passes over the cells). Same result, O(n * 60).
PointCount solve_point_count_bisection(const std::vector<float>& p);

// q_i = 1 - (1 - p_i)^(1/m) for the solved m (clamped p as above). O(n).
std::vector<float> densities(const std::vector<float>& p, const PointCount& pc);

struct Point {
  float x = 0, y = 0;  // continuous cell coordinates: cell (i, j) covers [i, i+1] x [j, j+1]
};

// Places `count` points with density proportional to q on a w x h grid by inverting the
// row-marginal and then the in-row CDF at the R2 low-discrepancy sequence (plastic-number
// Kronecker sequence), Cranley-Patterson rotated by the seed: deterministic per seed.
// Lookups go through guide tables (Chen 1974) and the points are counting-sorted by row
// so each row's CDF is built once: time O(n + count) expected, memory O(count + w + h)
// beyond q. The points come out in row order (top to bottom), which also suits a
// plotter. Returns nothing if q sums to 0.
std::vector<Point> place_points(const std::vector<float>& q, int w, int h, size_t count, uint64_t seed);

// Baseline for the benchmark and the evenness test: independent uniform draws inverted
// by binary search over the flat CDF (the textbook way). O(n + count log n).
std::vector<Point> place_points_random(const std::vector<float>& q, int w, int h, size_t count, uint64_t seed);

}  // namespace stipplot::sketch
