#pragma once
// Exact minimum spanning trees over points by Borůvka rounds on a kd-tree, under any
// edge cost that has a lower bound over a kd-tree box: the Euclidean MST (the planner's
// yardstick) and the tree method's anisotropic costs (methods/tree/mst.hpp).
//
// A cost policy C provides, for squared costs (so Euclidean needs no square root):
//   double c2(const Point& a, const Point& b) const;   the squared cost of edge (a, b)
//   double lb2(const Point& q, const Node& n) const;   <= c2(q, p) for every p in n's box
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <vector>

#include "geometry/drawing.hpp"
#include "spatial/kdtree.hpp"
#include "util/threads.hpp"

namespace stipplot::spatial {

struct Edge {
  uint32_t a = 0, b = 0;  // input indices
  double cost = 0;        // sqrt of the policy's squared cost
};

struct MstStats {
  int rounds = 0;
  size_t queries = 0;  // nearest-foreign-neighbour searches run
};

// Plain squared Euclidean distance, and the box distance as its bound.
template <int D, class T>
struct EuclideanCost {
  using Tree = KdTree<D, T>;
  double c2(const typename Tree::Point& a, const typename Tree::Point& b) const { return Tree::dist2(a, b); }
  double lb2(const typename Tree::Point& q, const typename Tree::Node& n) const { return Tree::box_dist2(n, q); }
};

// Exact MST by Borůvka rounds: each round every component finds its cheapest outgoing
// edge. A point's nearest foreign neighbour is cached between rounds (foreign sets only
// shrink, so a stale cost is a lower bound and a still-foreign one is exact); subtrees
// lying in one component are skipped; a search stops at its component's best cost so
// far. Ties are broken by (cost, lower tree position, higher tree position), so the
// rounds never close a cycle and the result does not depend on visiting order.
// A round's searches run on every thread (util/threads.hpp) from 20,000 points: the same
// edges in the same order on any count. Time O(n log n) to build plus O(log n) rounds of
// near-logarithmic queries on well-spread points; memory O(n). Returns n - 1 edges (none
// for n < 2).
template <int D, class T, class C>
std::vector<Edge> boruvka_mst(const KdTree<D, T>& tree, const C& cost, MstStats* stats = nullptr);

// The Euclidean MST of points in the plane (the lower bound a pen-up tour is measured
// against; also a source of realistic trees for tests).
std::vector<Edge> euclidean_mst(const std::vector<Vec2>& pts, MstStats* stats = nullptr);

double total_cost(const std::vector<Edge>& edges);

// ---- implementation ----

namespace detail {

struct UnionFind {
  std::vector<uint32_t> parent, size;
  explicit UnionFind(size_t n) : parent(n), size(n, 1) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  bool unite(uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    if (size[a] < size[b]) std::swap(a, b);
    parent[b] = a;
    size[a] += size[b];
    return true;
  }
};

// The cheapest edge from point q (tree position) to another component, better than a
// bound, under (cost, lower position, higher position).
template <int D, class T, class C>
struct ForeignSearch {
  using Tree = KdTree<D, T>;
  const Tree& t;
  const std::vector<int32_t>& comp;       // by tree position
  const std::vector<int32_t>& node_comp;  // shared component of a node's points, or -1
  const C cost;
  uint32_t q = 0;
  int32_t qc = 0;
  typename Tree::Point qp{};
  double best = std::numeric_limits<double>::infinity();
  uint32_t blo = kNone, bhi = kNone, bj = kNone;

  bool better(double c, uint32_t j) const {
    if (c != best) return c < best;
    const uint32_t lo = std::min(q, j), hi = std::max(q, j);
    return lo < blo || (lo == blo && hi < bhi);
  }
  void visit(uint32_t ni) {
    const auto& n = t.nodes()[ni];
    if (n.leaf()) {
      for (uint32_t i = n.begin; i < n.end; ++i) {
        if (comp[i] == qc) continue;
        const double c = cost.c2(qp, t.point(i));
        if (c <= best && better(c, i)) best = c, blo = std::min(q, i), bhi = std::max(q, i), bj = i;
      }
      return;
    }
    constexpr double inf = std::numeric_limits<double>::infinity();
    uint32_t a = n.left, b = n.right;
    double la = node_comp[a] == qc ? inf : cost.lb2(qp, t.nodes()[a]);
    double lb = node_comp[b] == qc ? inf : cost.lb2(qp, t.nodes()[b]);
    if (lb < la) std::swap(a, b), std::swap(la, lb);
    if (la <= best) visit(a);
    if (lb <= best) visit(b);
  }
};

// Labels every node with the component all its points share, or -1. Children come
// after their parent, so one backward pass sees them first. O(n).
template <int D, class T>
void label_nodes(const KdTree<D, T>& t, const std::vector<int32_t>& comp, std::vector<int32_t>& node_comp) {
  const auto& nodes = t.nodes();
  for (size_t k = nodes.size(); k-- > 0;) {
    const auto& nd = nodes[k];
    if (nd.leaf()) {
      int32_t c = comp[nd.begin];
      for (uint32_t i = nd.begin + 1; i < nd.end && c >= 0; ++i)
        if (comp[i] != c) c = -1;
      node_comp[k] = c;
    } else {
      const int32_t a = node_comp[nd.left], b = node_comp[nd.right];
      node_comp[k] = a == b ? a : -1;
    }
  }
}

}  // namespace detail

template <int D, class T, class C>
std::vector<Edge> boruvka_mst(const KdTree<D, T>& t, const C& cost, MstStats* stats) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const size_t n = t.size();
  std::vector<Edge> edges;
  if (n < 2) return edges;
  edges.reserve(n - 1);
  std::vector<uint32_t> nn(n, kNone);  // nearest foreign neighbour found last time
  std::vector<double> nnd(n, 0.0);     // its cost; a lower bound once nn is stale
  std::vector<int32_t> comp(n), node_comp(t.nodes().size());
  struct Best {
    double c;
    uint32_t lo, hi;
  };
  std::vector<Best> best(n);
  detail::UnionFind uf(n);
  size_t ncomp = n;
  MstStats st;
  auto offer = [&](int32_t r, double c, uint32_t i, uint32_t j) {
    Best& b = best[static_cast<size_t>(r)];
    const uint32_t lo = std::min(i, j), hi = std::max(i, j);
    if (c < b.c || (c == b.c && (lo < b.lo || (lo == b.lo && hi < b.hi)))) b = {c, lo, hi};
  };
  // Below this many points a round's searches take less than starting threads.
  constexpr size_t kWorthThreads = 20'000, kLocks = 4096;
  const bool parallel = n >= kWorthThreads && thread_count() > 1 && !in_parallel_part();
  std::unique_ptr<std::mutex[]> locks(parallel ? new std::mutex[kLocks] : nullptr);
  while (ncomp > 1) {
    ++st.rounds;
    for (uint32_t i = 0; i < n; ++i) comp[i] = static_cast<int32_t>(uf.find(i));
    detail::label_nodes(t, comp, node_comp);
    for (auto& b : best) b = {inf, kNone, kNone};
    // Cached neighbours still in another component are still exact.
    for (uint32_t i = 0; i < n; ++i) {
      if (nn[i] != kNone && comp[nn[i]] != comp[i])
        offer(comp[i], nnd[i], i, nn[i]);
      else
        nn[i] = kNone;
    }
    // The searches on every thread when worth it, each bounded by its component's best as
    // it stands when the search starts (read and offered under the component's lock). A
    // bound is always an edge the component has, so each component still ends the round
    // with its cheapest edge under (cost, lower, higher): the same tree bit for bit; only
    // how many searches run (the stats) depends on the threads' timing. On one thread the
    // searches go in tree order, each with the best so far.
    auto locked = [&](size_t r, auto&& f) {
      if (!parallel) return f();
      std::lock_guard<std::mutex> g(locks[r % kLocks]);
      return f();
    };
    size_t queries = 0;
#pragma omp parallel num_threads(thread_count()) reduction(+ : queries) if (parallel)
    {
      detail::ForeignSearch<D, T, C> s{t, comp, node_comp, cost};
#pragma omp for schedule(dynamic, 256)
      for (long k = 0; k < static_cast<long>(n); ++k) {
        const uint32_t i = static_cast<uint32_t>(k);
        if (nn[i] != kNone) continue;
        const size_t r = static_cast<size_t>(comp[i]);
        const Best b = locked(r, [&] { return best[r]; });
        if (nnd[i] > b.c) continue;  // cannot beat the component's best
        s.q = i, s.qc = comp[i], s.qp = t.point(i);
        s.best = b.c, s.blo = b.lo, s.bhi = b.hi, s.bj = kNone;
        ++queries;
        s.visit(0);
        if (s.bj != kNone) {
          nn[i] = s.bj, nnd[i] = s.best;
          locked(r, [&] { offer(comp[i], s.best, i, s.bj); });
        } else {
          nnd[i] = std::max(nnd[i], b.c);
        }
      }
    }
    st.queries += queries;
    const size_t before = ncomp;
    for (uint32_t r = 0; r < n; ++r) {
      if (comp[r] != static_cast<int32_t>(r) || best[r].lo == kNone) continue;
      if (uf.unite(best[r].lo, best[r].hi)) {
        edges.push_back({t.id(best[r].lo), t.id(best[r].hi), std::sqrt(best[r].c)});
        --ncomp;
      }
    }
    if (ncomp == before) break;  // only a NaN cost could leave a round without an edge
  }
  if (stats) *stats = st;
  return edges;
}

}  // namespace stipplot::spatial
