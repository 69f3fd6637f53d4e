#include "methods/tree/mst.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "spatial/mst.hpp"
#include "util/error.hpp"

namespace stipplot::tree {

namespace {

constexpr uint32_t kNone = spatial::kNone;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Points in (x, y, d): the kd-tree the MST searches.
using Tree = spatial::KdTree<3, float>;
using Pt = Tree::Point;
using Node = Tree::Node;

inline double gap(double v, float lo, float hi) { return v < lo ? lo - v : (v > hi ? v - hi : 0.0); }

// Cost policies: exact squared cost between points, a lower bound of it over a box, and
// how much the intensity counts when the kd-tree chooses where to split.
struct EdCost {
  double c2(const Pt& a, const Pt& b) const {
    const double dx = double(a[0]) - b[0], dy = double(a[1]) - b[1];
    return dx * dx + dy * dy;
  }
  double lb2(const Pt& q, const Node& n) const {
    const double gx = gap(q[0], n.lo[0], n.hi[0]), gy = gap(q[1], n.lo[1], n.hi[1]);
    return gx * gx + gy * gy;
  }
  double split_weight_z() const { return 0; }
};

struct BdCost {
  double alpha;
  double c2(const Pt& a, const Pt& b) const {
    const double dx = double(a[0]) - b[0], dy = double(a[1]) - b[1], dz = double(a[2]) - b[2];
    return dx * dx + dy * dy + alpha * (dz * dz);
  }
  double lb2(const Pt& q, const Node& n) const {
    const double gx = gap(q[0], n.lo[0], n.hi[0]), gy = gap(q[1], n.lo[1], n.hi[1]), gz = gap(q[2], n.lo[2], n.hi[2]);
    return gx * gx + gy * gy + alpha * (gz * gz);
  }
  // BD is Euclidean in (x, y, sqrt(α) d): split on the scaled intensity too.
  double split_weight_z() const { return std::sqrt(alpha); }
};

struct SibdCost {
  double alpha, h;
  double c2(const Pt& a, const Pt& b) const {
    const double dx = double(a[0]) - b[0], dy = double(a[1]) - b[1], dz = double(a[2]) - b[2];
    return dx * dx + dy * dy + alpha * std::max(h - dz * dz, 0.0);
  }
  // The penalty is smallest for the box's point farthest in intensity from q.
  double lb2(const Pt& q, const Node& n) const {
    const double gx = gap(q[0], n.lo[0], n.hi[0]), gy = gap(q[1], n.lo[1], n.hi[1]);
    const double far = std::max(std::abs(double(q[2]) - n.lo[2]), std::abs(double(q[2]) - n.hi[2]));
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

template <class C>
std::vector<Edge> boruvka(const PointSet& p, const C& cost, MstStats* stats) {
  const float* col[3] = {p.x.data(), p.y.data(), p.d.data()};
  const Tree t(p.size(), [&](uint32_t i, int k) { return col[k][i]; }, {1.0, 1.0, cost.split_weight_z()});
  return spatial::boruvka_mst(t, cost, stats);
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
