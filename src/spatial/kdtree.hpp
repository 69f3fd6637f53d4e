#pragma once
// The kd-tree of the pipeline's own spatial queries: the planner's greedy tours and the
// odd vertices it pairs (nearest point still present, with deletion), and exact minimum
// spanning trees (spatial/mst.hpp: nearest point of another component under any cost
// with box lower bounds). Static k-nearest lists come from nanoflann (spatial/knn.hpp).
//
// Static and balanced: median splits on the dimension of widest (weighted) extent, at
// most kLeafSize points a leaf, nodes in preorder (a node's children come after it) with
// tight bounding boxes. Points are stored in tree order, so a leaf's points are contiguous.
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "geometry/drawing.hpp"
#include "util/threads.hpp"

namespace stipplot::spatial {

inline constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();

template <int D, class T>
class KdTree {
 public:
  static constexpr uint32_t kLeafSize = 8;
  using Point = std::array<T, D>;
  struct Node {
    T lo[D], hi[D];           // bounding box of its points
    uint32_t begin, end;      // its points: tree positions [begin, end)
    uint32_t left = kNone, right = kNone;
    uint32_t alive = 0;       // its points not erased (read with the box by nearest searches)
    bool leaf() const { return left == kNone; }
  };

  // coord(i, k) is coordinate k of input point i (i < n). A dimension's extent is scaled
  // by split_weight[k] when choosing where to split (weight 0: never split on it); ties
  // go to the lower dimension. O(n log n) time, O(n) memory.
  template <class Coord>
  KdTree(size_t n, Coord&& coord, const std::array<double, D>& split_weight);

  size_t size() const { return pts_.size(); }
  const std::vector<Node>& nodes() const { return nodes_; }
  const Point& point(uint32_t pos) const { return pts_[pos]; }  // by tree position
  uint32_t id(uint32_t pos) const { return id_[pos]; }           // tree position -> input index

  static double dist2(const Point& a, const Point& b) {
    double s = 0;
    for (int k = 0; k < D; ++k) {
      const double d = double(a[k]) - b[k];
      s += d * d;
    }
    return s;
  }
  // Squared distance from q to the node's box (0 inside it).
  static double box_dist2(const Node& n, const Point& q) {
    double s = 0;
    for (int k = 0; k < D; ++k) {
      const double v = q[k];
      const double d = v < n.lo[k] ? n.lo[k] - v : (v > n.hi[k] ? v - n.hi[k] : 0.0);
      s += d * d;
    }
    return s;
  }

  // Deletion, for greedy constructions. alive(): points not erased.
  size_t alive() const { return nodes_.empty() ? 0 : nodes_[0].alive; }
  // Removes input point i from the nearest searches. O(log n).
  void erase(uint32_t i);
  // Input index of the nearest point not erased, which is erased: one step of a greedy
  // nearest-neighbour walk; kNone when none is left. Of equally near points it returns
  // the lowest index among those it reads: a box exactly as far as the best so far is
  // not opened, so the answer is deterministic but not always the lowest index of all
  // (the planner's plans depend on exactly this). Typically O(log n); empty subtrees
  // are skipped.
  uint32_t take_nearest(const Point& q) {
    const uint32_t pos = nearest_position(q);
    if (pos == kNone) return kNone;
    erase_position(pos);
    return id_[pos];
  }

 private:
  struct Item {
    Point p;
    uint32_t id;
  };
  // Builds the subtree of items [begin, end) as node `me` and its descendants after it;
  // `nodes_of(size)` is how many nodes a subtree of that many items has.
  template <class NodesOf>
  void build(uint32_t me, uint32_t begin, uint32_t end, std::vector<Item>& items, const std::array<double, D>& w,
             const NodesOf& nodes_of, bool tasks);
  // The bookkeeping deletion needs, made on the first erase (MSTs never erase). O(n).
  void prepare_erase();

  // nth_element of items[b, e) at mid by coordinate `dim`, the dimension a constant in
  // each comparator.
  template <int... K>
  static void median_split(std::vector<Item>& items, uint32_t b, uint32_t mid, uint32_t e, int dim,
                           std::integer_sequence<int, K...>) {
    auto by = [&](auto k) {
      std::nth_element(items.begin() + b, items.begin() + mid, items.begin() + e, [](const Item& x, const Item& y) {
        return x.p[decltype(k)::value] < y.p[decltype(k)::value];
      });
    };
    ((dim == K ? by(std::integral_constant<int, K>{}) : void()), ...);
  }
  uint32_t nearest_position(const Point& q) const;
  void erase_position(uint32_t pos);

  std::vector<Point> pts_;       // tree order
  std::vector<uint32_t> id_;     // tree position -> input index
  std::vector<Node> nodes_;
  // Made by prepare_erase:
  std::vector<uint32_t> pos_;      // input index -> tree position
  std::vector<uint32_t> parent_;   // per node (kNone for the root); kept out of Node, which searches read
  std::vector<uint32_t> leaf_of_;  // tree position -> its leaf
  std::vector<uint8_t> dead_;      // by tree position
};

template <int D, class T>
template <class Coord>
KdTree<D, T>::KdTree(size_t n, Coord&& coord, const std::array<double, D>& split_weight) {
  const uint32_t m = static_cast<uint32_t>(n);
  // Built on (point, index) items, so box scans and comparisons read contiguous memory;
  // nth_element moves items exactly as it would move indices, and leaves them in tree order.
  std::vector<Item> items(m);
  for (uint32_t i = 0; i < m; ++i) {
    for (int d = 0; d < D; ++d) items[i].p[d] = coord(i, d);
    items[i].id = i;
  }
  // Subtrees are halves (sizes floor and ceil of s / 2), so a level holds at most two sizes
  // and their node counts are found bottom-up in O(log n); each subtree's nodes then have
  // known places (preorder: a node, its left subtree, its right), and the two subtrees of a
  // large node are built at once on every thread: the same tree on any count.
  std::vector<std::pair<uint32_t, uint32_t>> counts;  // (size, nodes), distinct sizes
  for (std::vector<uint32_t> level = {m}; !level.empty();) {
    std::vector<uint32_t> next;
    for (const uint32_t sz : level) {
      counts.push_back({sz, 0});
      if (sz > kLeafSize)
        for (const uint32_t half : {sz / 2, sz - sz / 2})
          if (std::find(next.begin(), next.end(), half) == next.end()) next.push_back(half);
    }
    level = std::move(next);
  }
  auto nodes_of = [&counts](uint32_t sz) {
    for (const auto& [size, nodes] : counts)
      if (size == sz) return nodes;
    return uint32_t{0};
  };
  for (size_t k = counts.size(); k-- > 0;) {  // smallest sizes last in the list: fill them first
    auto& [sz, nodes] = counts[k];
    nodes = sz <= kLeafSize ? 1 : 1 + nodes_of(sz / 2) + nodes_of(sz - sz / 2);
  }
  if (m > 0) {
    nodes_.resize(nodes_of(m));
    const bool tasks = m >= 8'000 && thread_count() > 1 && !in_parallel_part();
    if (tasks) {
#pragma omp parallel num_threads(thread_count())
#pragma omp single
      build(0, 0, m, items, split_weight, nodes_of, true);
    } else {
      build(0, 0, m, items, split_weight, nodes_of, false);
    }
  }
  pts_.resize(m);
  id_.resize(m);
  for (uint32_t k = 0; k < m; ++k) {
    pts_[k] = items[k].p;
    id_[k] = items[k].id;
  }
}

template <int D, class T>
void KdTree<D, T>::prepare_erase() {
  const size_t m = pts_.size();
  dead_.assign(m, 0);
  pos_.resize(m);
  for (uint32_t k = 0; k < m; ++k) pos_[id_[k]] = k;
  parent_.assign(nodes_.size(), kNone);
  leaf_of_.assign(m, kNone);
  for (uint32_t i = 0; i < nodes_.size(); ++i) {
    const Node& n = nodes_[i];
    if (n.leaf()) {
      for (uint32_t k = n.begin; k < n.end; ++k) leaf_of_[k] = i;
    } else {
      parent_[n.left] = parent_[n.right] = i;
    }
  }
}

template <int D, class T>
template <class NodesOf>
void KdTree<D, T>::build(uint32_t me, uint32_t b, uint32_t e, std::vector<Item>& items, const std::array<double, D>& w,
                         const NodesOf& nodes_of, bool tasks) {
  Node nd{};
  nd.begin = b, nd.end = e, nd.alive = e - b;
  for (int k = 0; k < D; ++k) nd.lo[k] = std::numeric_limits<T>::max(), nd.hi[k] = std::numeric_limits<T>::lowest();
  for (uint32_t i = b; i < e; ++i) {
    const Point& p = items[i].p;
    for (int k = 0; k < D; ++k) nd.lo[k] = std::min(nd.lo[k], p[k]), nd.hi[k] = std::max(nd.hi[k], p[k]);
  }
  if (e - b > kLeafSize) {
    int dim = 0;
    double widest = (double(nd.hi[0]) - nd.lo[0]) * w[0];
    for (int k = 1; k < D; ++k) {
      const double ext = (double(nd.hi[k]) - nd.lo[k]) * w[k];
      if (ext > widest) widest = ext, dim = k;
    }
    const uint32_t mid = b + (e - b) / 2;
    median_split(items, b, mid, e, dim, std::make_integer_sequence<int, D>{});
    nd.left = me + 1;
    nd.right = me + 1 + nodes_of(mid - b);
    if (tasks && e - b >= 2'000) {  // a task each for large subtrees; small ones run here
#pragma omp task default(shared) firstprivate(nd, b, mid)
      build(nd.left, b, mid, items, w, nodes_of, true);
      build(nd.right, mid, e, items, w, nodes_of, true);
#pragma omp taskwait
    } else {
      build(nd.left, b, mid, items, w, nodes_of, false);
      build(nd.right, mid, e, items, w, nodes_of, false);
    }
  }
  nodes_[me] = nd;
}

template <int D, class T>
void KdTree<D, T>::erase(uint32_t i) {
  if (dead_.empty()) prepare_erase();
  erase_position(pos_[i]);
}

template <int D, class T>
void KdTree<D, T>::erase_position(uint32_t p) {
  if (dead_.empty()) prepare_erase();
  if (dead_[p]) return;
  dead_[p] = 1;
  for (uint32_t n = leaf_of_[p]; n != kNone; n = parent_[n]) --nodes_[n].alive;
}

// Returns the tree position; ties go to the lower input index.
template <int D, class T>
uint32_t KdTree<D, T>::nearest_position(const Point& q) const {
  uint32_t best = kNone, best_id = kNone;
  if (alive() == 0) return best;
  const uint8_t* dead = dead_.empty() ? nullptr : dead_.data();
  double best_d2 = std::numeric_limits<double>::infinity();
  uint32_t stack[128];  // depth is log2(n / kLeafSize) + 1, far below this
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const uint32_t ni = stack[--sp];
    const Node& n = nodes_[ni];
    if (n.alive == 0 || box_dist2(n, q) >= best_d2) continue;
    if (n.leaf()) {
      for (uint32_t k = n.begin; k < n.end; ++k) {
        if (dead && dead[k]) continue;
        const double d2 = dist2(pts_[k], q);
        if (d2 < best_d2 || (d2 == best_d2 && id_[k] < best_id)) best_d2 = d2, best = k, best_id = id_[k];
      }
      continue;
    }
    // The farther child goes on the stack first, so the nearer one is searched first.
    if (box_dist2(nodes_[n.left], q) <= box_dist2(nodes_[n.right], q)) {
      stack[sp++] = n.right;
      stack[sp++] = n.left;
    } else {
      stack[sp++] = n.left;
      stack[sp++] = n.right;
    }
  }
  return best;
}

// Points on the page (mm): the planner's tree.
using PlaneTree = KdTree<2, double>;
inline PlaneTree plane_tree(const std::vector<Vec2>& pts) {
  return PlaneTree(pts.size(), [&](uint32_t i, int k) { return k == 0 ? pts[i].x : pts[i].y; }, {1.0, 1.0});
}
inline PlaneTree::Point plane_point(Vec2 p) { return {p.x, p.y}; }

}  // namespace stipplot::spatial
