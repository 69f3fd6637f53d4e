#include "plan/emst.hpp"

#include <cmath>
#include <limits>
#include <numeric>

#include "plan/kdtree.hpp"

namespace stipplot::plan {

namespace {
struct Dsu {
  std::vector<uint32_t> p;
  explicit Dsu(size_t n) : p(n) { std::iota(p.begin(), p.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (p[x] != x) x = p[x] = p[p[x]];
    return x;
  }
  bool unite(uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    if (a < b) std::swap(a, b);
    p[a] = b;
    return true;
  }
};
}  // namespace

std::vector<Edge> euclidean_mst(const std::vector<Vec2>& pts) {
  const uint32_t n = static_cast<uint32_t>(pts.size());
  std::vector<Edge> out;
  if (n < 2) return out;
  out.reserve(n - 1);
  KdTree tree(pts);
  Dsu dsu(n);
  std::vector<uint32_t> comp(n);
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::vector<double> best_d2(n);
  std::vector<uint32_t> best_a(n), best_b(n);
  while (out.size() + 1 < n) {
    for (uint32_t i = 0; i < n; ++i) comp[i] = dsu.find(i);
    tree.set_components(comp);
    std::fill(best_d2.begin(), best_d2.end(), inf);
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t c = comp[i];
      double bound = best_d2[c];
      // Equal lengths may let two components pick edges that close a cycle; the
      // union-find below skips such an edge, and the tree stays minimal.
      const uint32_t j = tree.nearest_other(i, bound);  // only if closer than bound
      if (j == UINT32_MAX) continue;
      best_d2[c] = bound;
      best_a[c] = i;
      best_b[c] = j;
    }
    size_t before = out.size();
    for (uint32_t c = 0; c < n; ++c) {
      if (comp[c] != c || best_d2[c] == inf) continue;
      if (dsu.unite(best_a[c], best_b[c]))
        out.push_back({best_a[c], best_b[c], std::sqrt(best_d2[c])});
    }
    if (out.size() == before) break;  // cannot happen for finite points; guards a hang
  }
  return out;
}

double total_length(const std::vector<Edge>& edges) {
  double s = 0;
  for (const Edge& e : edges) s += e.length;
  return s;
}

}  // namespace stipplot::plan
