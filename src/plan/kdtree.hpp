#pragma once
// A small static 2-d tree over points that supports what nanoflann does not:
// deleting points (greedy nearest-neighbour tours) and "nearest point of another
// component" queries (Borůvka minimum spanning trees). Leaves hold up to 8 points.
#include <cstdint>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::plan {

class KdTree {
 public:
  // O(n log n) build. The points must outlive the tree.
  explicit KdTree(const std::vector<Vec2>& pts);

  size_t size() const { return pts_.size(); }
  size_t alive() const { return nodes_.empty() ? 0 : nodes_[0].count; }

  // Removes point i from nearest_alive's view. O(log n).
  void erase(uint32_t i);
  // Nearest point still present, or UINT32_MAX when none is. Typically O(log n);
  // degrades gracefully as regions empty because empty subtrees are skipped.
  uint32_t nearest_alive(Vec2 q) const;

  // Labels every point with a component id (comp[i]); nodes whose points all share
  // one id are pruned by nearest_other. O(n).
  void set_components(const std::vector<uint32_t>& comp);
  // Nearest point whose component differs from comp[self], closer than sqrt(bound2);
  // returns UINT32_MAX if none. bound2 is updated to the squared distance found.
  uint32_t nearest_other(uint32_t self, double& bound2) const;

 private:
  struct Node {
    double lox, loy, hix, hiy;
    uint32_t begin, end;     // range in idx_
    int32_t left = -1, right = -1, parent = -1;
    uint32_t count = 0;      // points still present below
    uint32_t comp = 0;       // shared component id, or kMixed
  };
  static constexpr uint32_t kMixed = UINT32_MAX;
  int32_t build(uint32_t begin, uint32_t end, int32_t parent);
  uint32_t label(int32_t node);
  static double box_dist2(const Node& n, Vec2 q);

  const std::vector<Vec2>& pts_;
  std::vector<uint32_t> idx_;      // point indices, grouped by leaf
  std::vector<int32_t> leaf_of_;   // point -> leaf node
  std::vector<Node> nodes_;
  std::vector<uint8_t> dead_;
  const std::vector<uint32_t>* comp_ = nullptr;
};

}  // namespace stipplot::plan
