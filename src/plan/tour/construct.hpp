#pragma once
// First paths for the improver: every node once, each stroke's two ends adjacent.
#include <cstdint>
#include <vector>

#include "candidates.hpp"
#include "geometry/drawing.hpp"

namespace stipplot::plan::tour {

// Greedy nearest neighbour from `start` over a kd-tree with deletion: O(n log n).
// About 25 % above an optimal tour on uniform points.
std::vector<uint32_t> nearest_neighbour_path(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner,
                                             Vec2 start);

// Greedy edge matching: candidate edges shortest first, each taken unless it gives a
// node a third edge or closes a cycle (strokes' own edges are taken first); the
// fragments are then chained nearest end first from `start`. O(n k log(n k)) for the
// sort, O(f log f) for f fragments. Some 14-20 % above optimal on uniform points, and
// a start from which 2-opt needs fewer and shorter moves than from nearest neighbour.
std::vector<uint32_t> greedy_edge_path(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                                       const Candidates& cand);

}  // namespace stipplot::plan::tour
