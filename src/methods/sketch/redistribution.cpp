#include "methods/sketch/redistribution.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "util/rng.hpp"

namespace stipplot::sketch {

double max_probability() { return -std::expm1(-kMaxPointsPerCell); }

namespace {

// a_i = -ln(1 - p_i) of the cells with p > 0, clamped; the cells with p = 0 add nothing
// to h(s), so they are dropped once here.
std::vector<double> positive_logs(const std::vector<float>& p) {
  std::vector<double> a;
  a.reserve(p.size() / 4);
  for (float v : p)
    if (v > 0) a.push_back(-std::log1p(-std::min<double>(v, max_probability())));
  return a;
}

// h(s) - 1 and h'(s).
void eval(const std::vector<double>& a, double s, double& f, double& df) {
  double sum = 0, d = 0;
  for (double ai : a) {
    const double e = std::exp(-s * ai);
    sum += 1.0 - e;
    d += ai * e;
  }
  f = sum - 1.0;
  df = d;
}

bool degenerate(const std::vector<double>& a, PointCount& pc) {
  if (a.size() >= 2) return false;
  pc.degenerate = true;
  pc.m = a.empty() ? 0.0 : a[0];
  pc.s = pc.m > 0 ? 1.0 / pc.m : 0.0;
  return true;
}

double sum_of(const std::vector<double>& a) {
  double t = 0;
  for (double v : a) t += v;
  return t;
}

}  // namespace

PointCount solve_point_count(const std::vector<float>& p) {
  PointCount pc;
  const std::vector<double> a = positive_logs(p);
  if (degenerate(a, pc)) return pc;
  // h(s) <= s * sum a, so s0 = 1/sum a is at or below the root; Newton on a concave
  // increasing function from below never overshoots.
  double s = 1.0 / sum_of(a);
  for (pc.iterations = 1; pc.iterations <= 100; ++pc.iterations) {
    double f, df;
    eval(a, s, f, df);
    if (!(df > 0)) break;  // every term saturated: s already huge
    const double step = -f / df;
    s += step;
    if (std::abs(step) <= 1e-13 * s) break;
  }
  pc.s = s;
  pc.m = 1.0 / s;
  return pc;
}

PointCount solve_point_count_bisection(const std::vector<float>& p) {
  PointCount pc;
  const std::vector<double> a = positive_logs(p);
  if (degenerate(a, pc)) return pc;
  double lo = 0, hi = 1.0 / sum_of(a), f, df;
  for (eval(a, hi, f, df); f < 0; eval(a, hi, f, df)) {
    lo = hi;
    hi *= 2;
    ++pc.iterations;
  }
  while (hi - lo > 1e-13 * hi) {
    const double mid = 0.5 * (lo + hi);
    eval(a, mid, f, df);
    (f < 0 ? lo : hi) = mid;
    ++pc.iterations;
  }
  pc.s = 0.5 * (lo + hi);
  pc.m = 1.0 / pc.s;
  return pc;
}

std::vector<float> densities(const std::vector<float>& p, const PointCount& pc) {
  std::vector<float> q(p.size(), 0.0f);
  const double pmax = max_probability();
  for (size_t i = 0; i < p.size(); ++i)
    if (p[i] > 0) q[i] = static_cast<float>(-std::expm1(pc.s * std::log1p(-std::min<double>(p[i], pmax))));
  return q;
}

namespace {

// Guide table (Chen 1974) over a cumulative array: guide[k] is the first index whose
// cumulative value exceeds k/G of the total, so an inversion starts next to its answer
// and walks O(1) steps on average.
template <typename T>
void build_guide(const T* cum, size_t n, double total, std::vector<uint32_t>& guide) {
  const size_t g = n;
  guide.resize(g);
  size_t i = 0;
  const double step = total / static_cast<double>(g);
  for (size_t k = 0; k < g; ++k) {
    const double target = step * static_cast<double>(k);
    while (i + 1 < n && static_cast<double>(cum[i]) <= target) ++i;
    guide[k] = static_cast<uint32_t>(i);
  }
}

// The index i with cum[i-1] <= u*total < cum[i], plus the fraction of the way through it.
template <typename T>
double invert(const std::vector<uint32_t>& guide, const T* cum, size_t n, double u, double total) {
  const double target = u * total;
  size_t i = guide[std::min(guide.size() - 1, static_cast<size_t>(u * static_cast<double>(guide.size())))];
  while (i + 1 < n && static_cast<double>(cum[i]) <= target) ++i;
  const double before = i ? static_cast<double>(cum[i - 1]) : 0.0;
  const double width = static_cast<double>(cum[i]) - before;
  const double f = width > 0 ? std::clamp((target - before) / width, 0.0, 0.999999) : 0.5;
  return static_cast<double>(i) + f;
}

}  // namespace

std::vector<Point> place_points(const std::vector<float>& q, int w, int h, size_t count, uint64_t seed) {
  if (w <= 0 || h <= 0 || q.size() != static_cast<size_t>(w) * static_cast<size_t>(h))
    throw std::invalid_argument("place_points: q does not match the grid");
  std::vector<Point> out;
  // The row marginal: one sequential pass over q.
  std::vector<double> row_cum(h);
  double total = 0;
  for (int y = 0; y < h; ++y) {
    const float* row = q.data() + static_cast<size_t>(y) * w;
    double r = 0;
    for (int x = 0; x < w; ++x) r += std::max(0.0f, row[x]);
    row_cum[y] = (total += r);
  }
  if (!(total > 0) || count == 0) return out;
  std::vector<uint32_t> guide;
  build_guide(row_cum.data(), h, total, guide);

  // R2 sequence: Kronecker steps 1/g, 1/g^2 with g the plastic number, shifted by the
  // seed (Cranley-Patterson rotation). Two passes over the (cheap) sequence: count the
  // points of each row, then write each point straight to its row's slot, so that each
  // row's CDF is built once and the points are read in order (no random reads: the
  // cost per cell stays nearly flat as the grid grows).
  Rng rng(seed ^ 0x5ce7c4u);
  const double shift1 = rng.uniform(), shift2 = rng.uniform();
  constexpr double g = 1.32471795724474602596;
  constexpr double a1 = 1.0 / g, a2 = 1.0 / (g * g);
  std::vector<uint32_t> start(static_cast<size_t>(h) + 1, 0);
  {
    double u1 = shift1;
    for (size_t i = 0; i < count; ++i) {
      u1 += a1;
      if (u1 >= 1) u1 -= 1;
      const int y = std::min(h - 1, static_cast<int>(invert(guide, row_cum.data(), h, u1, total)));
      ++start[y + 1];
    }
  }
  for (int y = 0; y < h; ++y) start[y + 1] += start[y];
  std::vector<float> ys(count), us(count);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    double u1 = shift1, u2 = shift2;
    for (size_t i = 0; i < count; ++i) {
      u1 += a1;
      if (u1 >= 1) u1 -= 1;
      u2 += a2;
      if (u2 >= 1) u2 -= 1;
      const double yc = invert(guide, row_cum.data(), h, u1, total);
      const uint32_t k = fill[std::min(h - 1, static_cast<int>(yc))]++;
      ys[k] = static_cast<float>(yc);
      us[k] = static_cast<float>(u2);
    }
  }
  out.resize(count);
  std::vector<float> cum(w);
  for (int y = 0; y < h; ++y) {
    if (start[y] == start[y + 1]) continue;
    const float* row = q.data() + static_cast<size_t>(y) * w;
    double r = 0;
    for (int x = 0; x < w; ++x) cum[x] = static_cast<float>(r += std::max(0.0f, row[x]));
    build_guide(cum.data(), w, r, guide);
    for (uint32_t k = start[y]; k < start[y + 1]; ++k)
      out[k] = {static_cast<float>(invert(guide, cum.data(), w, us[k], r)), ys[k]};
  }
  return out;
}

std::vector<Point> place_points_random(const std::vector<float>& q, int w, int h, size_t count, uint64_t seed) {
  if (w <= 0 || h <= 0 || q.size() != static_cast<size_t>(w) * static_cast<size_t>(h))
    throw std::invalid_argument("place_points_random: q does not match the grid");
  std::vector<double> cum(q.size());
  double t = 0;
  for (size_t i = 0; i < q.size(); ++i) cum[i] = (t += std::max(0.0f, q[i]));
  std::vector<Point> out;
  if (!(t > 0)) return out;
  out.reserve(count);
  Rng rng(seed);
  for (size_t i = 0; i < count; ++i) {
    const double u = rng.uniform() * t;
    size_t k = static_cast<size_t>(std::upper_bound(cum.begin(), cum.end(), u) - cum.begin());
    k = std::min(k, q.size() - 1);
    out.push_back({static_cast<float>(k % w + rng.uniform()), static_cast<float>(k / w + rng.uniform())});
  }
  return out;
}

}  // namespace stipplot::sketch
