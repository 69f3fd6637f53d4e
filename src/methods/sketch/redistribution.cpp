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

// Inverse CDF through a guide table: guide[k] is the first index whose cumulative
// value exceeds k/G of the total, so a lookup starts next to its answer.
struct Inverter {
  std::vector<uint32_t> guide;
  void build(const double* cum, size_t n, double total) {
    const size_t g = n;
    guide.assign(g, 0);
    size_t i = 0;
    for (size_t k = 0; k < g; ++k) {
      const double target = total * static_cast<double>(k) / static_cast<double>(g);
      while (i + 1 < n && cum[i] <= target) ++i;
      guide[k] = static_cast<uint32_t>(i);
    }
  }
  // Index i with cum[i-1] <= u*total < cum[i], and the fraction inside it.
  template <typename T>
  static double find(const std::vector<uint32_t>& guide, const T* cum, size_t n, double u, double total) {
    const double target = u * total;
    size_t k = std::min(guide.size() - 1, static_cast<size_t>(u * static_cast<double>(guide.size())));
    size_t i = guide[k];
    while (i + 1 < n && static_cast<double>(cum[i]) <= target) ++i;
    const double before = i ? static_cast<double>(cum[i - 1]) : 0.0;
    const double width = static_cast<double>(cum[i]) - before;
    const double f = width > 0 ? std::clamp((target - before) / width, 0.0, 0.999999) : 0.5;
    return static_cast<double>(i) + f;
  }
};

}  // namespace

std::vector<Point> place_points(const std::vector<float>& q, int w, int h, size_t count, uint64_t seed) {
  if (w <= 0 || h <= 0 || q.size() != static_cast<size_t>(w) * static_cast<size_t>(h))
    throw std::invalid_argument("place_points: q does not match the grid");
  std::vector<Point> out;
  // Row sums and the marginal CDF; in-row CDFs in float (relative to the row).
  std::vector<double> row_cum(h);
  std::vector<float> cum(q.size());
  double total = 0;
  for (int y = 0; y < h; ++y) {
    double r = 0;
    const size_t o = static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      r += std::max(0.0f, q[o + x]);
      cum[o + x] = static_cast<float>(r);
    }
    total += r;
    row_cum[y] = total;
  }
  if (!(total > 0) || count == 0) return out;
  Inverter rows;
  rows.build(row_cum.data(), h, total);
  // One guide table per row with points in it, built on first use: O(w) each.
  std::vector<uint32_t> row_guides(q.size());
  std::vector<uint8_t> built(h, 0);
  Rng rng(seed ^ 0x5ce7c4u);
  const double shift1 = rng.uniform(), shift2 = rng.uniform();
  // R2 sequence: Kronecker steps 1/g, 1/g^2 with g the plastic number.
  constexpr double g = 1.32471795724474602596;
  constexpr double a1 = 1.0 / g, a2 = 1.0 / (g * g);
  double u1 = shift1, u2 = shift2;
  out.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    u1 += a1;
    if (u1 >= 1) u1 -= 1;
    u2 += a2;
    if (u2 >= 1) u2 -= 1;
    const double yc = Inverter::find(rows.guide, row_cum.data(), h, u1, total);
    const int y = std::min(h - 1, static_cast<int>(yc));
    const size_t o = static_cast<size_t>(y) * w;
    const float* rc = cum.data() + o;
    const double rt = rc[w - 1];
    uint32_t* gd = row_guides.data() + o;
    if (!built[y]) {
      size_t j = 0;
      for (int k = 0; k < w; ++k) {
        const double target = rt * k / w;
        while (j + 1 < static_cast<size_t>(w) && rc[j] <= target) ++j;
        gd[k] = static_cast<uint32_t>(j);
      }
      built[y] = 1;
    }
    // Find with the row's guide (a span of the big table).
    const double target = u2 * rt;
    size_t k = std::min<size_t>(w - 1, static_cast<size_t>(u2 * w));
    size_t j = gd[k];
    while (j + 1 < static_cast<size_t>(w) && static_cast<double>(rc[j]) <= target) ++j;
    const double before = j ? static_cast<double>(rc[j - 1]) : 0.0;
    const double width = static_cast<double>(rc[j]) - before;
    const double f = width > 0 ? std::clamp((target - before) / width, 0.0, 0.999999) : 0.5;
    out.push_back({static_cast<float>(j + f), static_cast<float>(yc)});
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
