#include "methods/tree/mst.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "util/error.hpp"

namespace stipplot::tree {

namespace {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Pt {
  float x, y, z;
};

// Node of the kd-tree: bounding box in (x, y, d), its points [begin, end) in tree
// order, and the component shared by all its points (-1 if mixed) for this round.
struct Node {
  float lo[3], hi[3];
  uint32_t begin, end;
  uint32_t left = kNone, right = kNone;
  int32_t comp = -1;
  bool leaf() const { return left == kNone; }
};

inline double gap(double v, float lo, float hi) { return v < lo ? lo - v : (v > hi ? v - hi : 0.0); }

// Cost policies: exact squared cost between points, and a lower bound of it over a box.
struct EdCost {
  double c2(const Pt& a, const Pt& b) const {
    const double dx = double(a.x) - b.x, dy = double(a.y) - b.y;
    return dx * dx + dy * dy;
  }
  double lb2(const Pt& q, const Node& n) const {
    const double gx = gap(q.x, n.lo[0], n.hi[0]), gy = gap(q.y, n.lo[1], n.hi[1]);
    return gx * gx + gy * gy;
  }
  double split_weight_z() const { return 0; }
};

struct BdCost {
  double alpha;
  double c2(const Pt& a, const Pt& b) const {
    const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
    return dx * dx + dy * dy + alpha * (dz * dz);
  }
  double lb2(const Pt& q, const Node& n) const {
    const double gx = gap(q.x, n.lo[0], n.hi[0]), gy = gap(q.y, n.lo[1], n.hi[1]), gz = gap(q.z, n.lo[2], n.hi[2]);
    return gx * gx + gy * gy + alpha * (gz * gz);
  }
  // BD is Euclidean in (x, y, sqrt(α) d): split on the scaled intensity too.
  double split_weight_z() const { return std::sqrt(alpha); }
};

struct SibdCost {
  double alpha, h;
  double c2(const Pt& a, const Pt& b) const {
    const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
    return dx * dx + dy * dy + alpha * std::max(h - dz * dz, 0.0);
  }
  // The penalty is smallest for the box's point farthest in intensity from q.
  double lb2(const Pt& q, const Node& n) const {
    const double gx = gap(q.x, n.lo[0], n.hi[0]), gy = gap(q.y, n.lo[1], n.hi[1]);
    const double far = std::max(std::abs(double(q.z) - n.lo[2]), std::abs(double(q.z) - n.hi[2]));
    return gx * gx + gy * gy + alpha * std::max(h - far * far, 0.0);
  }
  double split_weight_z() const { return 0; }
};

template <class F>
decltype(auto) with_cost(const CostParams& c, F&& f) {
  switch (c.kind) {
    case Distance::BD: return f(BdCost{c.alpha});
    case Distance::SIBD: return f(SibdCost{c.alpha, c.h});
    case Distance::ED: break;
  }
  return f(EdCost{});
}

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

class KdTree {
 public:
  static constexpr uint32_t kLeaf = 8;
  std::vector<Pt> pts;        // tree order
  std::vector<uint32_t> id;   // tree order -> input index
  std::vector<Node> nodes;    // preorder: children after parents

  KdTree(const PointSet& p, double wz) : src_(p), wz_(wz) {
    const size_t n = p.size();
    id.resize(n);
    std::iota(id.begin(), id.end(), 0u);
    nodes.reserve(2 * n / kLeaf + 2);
    if (n) build(0, static_cast<uint32_t>(n));
    pts.resize(n);
    for (size_t k = 0; k < n; ++k) pts[k] = {p.x[id[k]], p.y[id[k]], p.d[id[k]]};
  }

 private:
  const PointSet& src_;
  double wz_;
  // Median split on the widest side; O(n log n) in all.
  uint32_t build(uint32_t b, uint32_t e) {
    const uint32_t me = static_cast<uint32_t>(nodes.size());
    nodes.push_back(Node{});
    Node nd{};
    nd.begin = b, nd.end = e;
    nd.lo[0] = nd.lo[1] = nd.lo[2] = std::numeric_limits<float>::max();
    nd.hi[0] = nd.hi[1] = nd.hi[2] = std::numeric_limits<float>::lowest();
    const float* col[3] = {src_.x.data(), src_.y.data(), src_.d.data()};
    for (uint32_t i = b; i < e; ++i)
      for (int k = 0; k < 3; ++k) {
        const float v = col[k][id[i]];
        nd.lo[k] = std::min(nd.lo[k], v), nd.hi[k] = std::max(nd.hi[k], v);
      }
    if (e - b > kLeaf) {
      const double ext[3] = {double(nd.hi[0]) - nd.lo[0], double(nd.hi[1]) - nd.lo[1],
                             (double(nd.hi[2]) - nd.lo[2]) * wz_};
      const int dim = ext[0] >= ext[1] ? (ext[0] >= ext[2] ? 0 : 2) : (ext[1] >= ext[2] ? 1 : 2);
      const uint32_t m = b + (e - b) / 2;
      const float* key = col[dim];
      std::nth_element(id.begin() + b, id.begin() + m, id.begin() + e,
                       [key](uint32_t i, uint32_t j) { return key[i] < key[j]; });
      nd.left = build(b, m);
      nd.right = build(m, e);
    }
    nodes[me] = nd;
    return me;
  }
};

// Nearest point of another component under a cost policy, better than a bound.
template <class C>
struct ForeignSearch {
  const KdTree& t;
  const std::vector<int32_t>& comp;
  C cost;
  uint32_t q = 0;
  int32_t qc = 0;
  Pt qp{};
  double best = kInf;
  uint32_t blo = kNone, bhi = kNone, bj = kNone;

  bool better(double c, uint32_t j) const {
    if (c != best) return c < best;
    const uint32_t lo = std::min(q, j), hi = std::max(q, j);
    return lo < blo || (lo == blo && hi < bhi);
  }
  void visit(uint32_t ni) {
    const Node& n = t.nodes[ni];
    if (n.leaf()) {
      for (uint32_t i = n.begin; i < n.end; ++i) {
        if (comp[i] == qc) continue;
        const double c = cost.c2(qp, t.pts[i]);
        if (c <= best && better(c, i)) best = c, blo = std::min(q, i), bhi = std::max(q, i), bj = i;
      }
      return;
    }
    uint32_t a = n.left, b = n.right;
    double la = t.nodes[a].comp == qc ? kInf : cost.lb2(qp, t.nodes[a]);
    double lb = t.nodes[b].comp == qc ? kInf : cost.lb2(qp, t.nodes[b]);
    if (lb < la) std::swap(a, b), std::swap(la, lb);
    if (la <= best) visit(a);
    if (lb <= best) visit(b);
  }
};

template <class C>
std::vector<Edge> boruvka(const PointSet& p, C cost, MstStats* stats) {
  const size_t n = p.size();
  std::vector<Edge> edges;
  if (n < 2) return edges;
  edges.reserve(n - 1);
  KdTree t(p, cost.split_weight_z());
  std::vector<uint32_t> nn(n, kNone);  // nearest foreign neighbour found last time
  std::vector<double> nnd(n, 0.0);     // its cost; a lower bound once nn is stale
  std::vector<int32_t> comp(n);
  struct Best {
    double c;
    uint32_t lo, hi;
  };
  std::vector<Best> best(n);
  UnionFind uf(n);
  size_t ncomp = n;
  MstStats st;
  ForeignSearch<C> s{t, comp, cost};
  auto offer = [&](int32_t r, double c, uint32_t i, uint32_t j) {
    Best& b = best[static_cast<size_t>(r)];
    const uint32_t lo = std::min(i, j), hi = std::max(i, j);
    if (c < b.c || (c == b.c && (lo < b.lo || (lo == b.lo && hi < b.hi)))) b = {c, lo, hi};
  };
  while (ncomp > 1) {
    ++st.rounds;
    for (uint32_t i = 0; i < n; ++i) comp[i] = static_cast<int32_t>(uf.find(i));
    for (size_t k = t.nodes.size(); k-- > 0;) {
      Node& nd = t.nodes[k];
      if (nd.leaf()) {
        int32_t c = comp[nd.begin];
        for (uint32_t i = nd.begin + 1; i < nd.end && c >= 0; ++i)
          if (comp[i] != c) c = -1;
        nd.comp = c;
      } else {
        const int32_t a = t.nodes[nd.left].comp, b = t.nodes[nd.right].comp;
        nd.comp = a == b ? a : -1;
      }
    }
    for (auto& b : best) b = {kInf, kNone, kNone};
    // Cached neighbours still in another component are still exact.
    for (uint32_t i = 0; i < n; ++i) {
      if (nn[i] != kNone && comp[nn[i]] != comp[i])
        offer(comp[i], nnd[i], i, nn[i]);
      else
        nn[i] = kNone;
    }
    for (uint32_t i = 0; i < n; ++i) {
      if (nn[i] != kNone) continue;
      const Best& b = best[static_cast<size_t>(comp[i])];
      if (nnd[i] > b.c) continue;  // cannot beat the component's best
      s.q = i, s.qc = comp[i], s.qp = t.pts[i];
      s.best = b.c, s.blo = b.lo, s.bhi = b.hi, s.bj = kNone;
      ++st.queries;
      s.visit(0);
      if (s.bj != kNone) {
        nn[i] = s.bj, nnd[i] = s.best;
        offer(comp[i], s.best, i, s.bj);
      } else {
        nnd[i] = std::max(nnd[i], b.c);
      }
    }
    for (uint32_t r = 0; r < n; ++r) {
      if (comp[r] != static_cast<int32_t>(r) || best[r].lo == kNone) continue;
      if (uf.unite(best[r].lo, best[r].hi)) {
        edges.push_back({t.id[best[r].lo], t.id[best[r].hi], std::sqrt(best[r].c)});
        --ncomp;
      }
    }
  }
  if (stats) *stats = st;
  return edges;
}

template <class C>
std::vector<Edge> prim(const PointSet& p, C cost) {
  const size_t n = p.size();
  std::vector<Edge> edges;
  if (n < 2) return edges;
  std::vector<Pt> pts(n);
  for (size_t i = 0; i < n; ++i) pts[i] = {p.x[i], p.y[i], p.d[i]};
  struct Slot {
    double key = kInf;  // cheapest squared cost to the tree so far
    uint32_t parent = kNone;
    bool in = false;
  };
  std::vector<Slot> v(n);
  uint32_t cur = 0;
  for (size_t step = 0; step < n; ++step) {
    v[cur].in = true;
    if (v[cur].parent != kNone) edges.push_back({v[cur].parent, cur, std::sqrt(v[cur].key)});
    uint32_t next = kNone;
    double nb = kInf;
    const Pt pc = pts[cur];
    for (uint32_t j = 0; j < n; ++j) {
      Slot& s = v[j];
      if (s.in) continue;
      const double c = cost.c2(pc, pts[j]);
      if (c < s.key) s.key = c, s.parent = cur;
      if (s.key < nb) nb = s.key, next = j;
    }
    if (next == kNone) break;
    cur = next;
  }
  return edges;
}

}  // namespace

void CostParams::validate() const {
  require_range("--alpha", alpha, 0, 1e6);
  require_range("--h", h, 0, 1e9);
}

double edge_cost2(const PointSet& p, const CostParams& c, uint32_t i, uint32_t j) {
  const Pt a{p.x[i], p.y[i], p.d[i]}, b{p.x[j], p.y[j], p.d[j]};
  return with_cost(c, [&](auto cost) { return cost.c2(a, b); });
}

std::vector<Edge> mst_prim_reference(const PointSet& p, const CostParams& c) {
  return with_cost(c, [&](auto cost) { return prim(p, cost); });
}

std::vector<Edge> mst_exact(const PointSet& p, const CostParams& c, MstStats* stats) {
  return with_cost(c, [&](auto cost) { return boruvka(p, cost, stats); });
}

double total_cost(const std::vector<Edge>& edges) {
  double s = 0;
  for (const auto& e : edges) s += e.cost;
  return s;
}

Distance parse_distance(const std::string& name) {
  if (name == "ed") return Distance::ED;
  if (name == "bd") return Distance::BD;
  if (name == "sibd") return Distance::SIBD;
  throw UserError("--distance: unknown distance '" + name + "' (use ed, bd or sibd)");
}

const char* to_string(Distance d) {
  switch (d) {
    case Distance::ED: return "ed";
    case Distance::BD: return "bd";
    case Distance::SIBD: return "sibd";
  }
  return "?";
}

}  // namespace stipplot::tree
