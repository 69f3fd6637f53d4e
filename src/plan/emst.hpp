#pragma once
// Exact Euclidean minimum spanning tree: the lower bound the planner's travel is
// measured against, and a source of realistic trees for tests.
#include <cstdint>
#include <utility>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::plan {

struct Edge {
  uint32_t a, b;
  double length;
};

// Borůvka over a kd-tree whose nodes know when all their points lie in one
// component: each round finds every component's exact nearest outside point.
// O(n log n) per round expected for spread-out points, at most log2 n rounds.
// Returns n-1 edges (fewer only if n < 2).
std::vector<Edge> euclidean_mst(const std::vector<Vec2>& pts);

double total_length(const std::vector<Edge>& edges);

}  // namespace stipplot::plan
