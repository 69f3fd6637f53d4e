#pragma once
// Candidate lists: the k nearest other nodes of every node, the moves' only partners.
#include <cstdint>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::plan::tour {

inline constexpr uint32_t kNoNode = UINT32_MAX;

struct Candidates {
  uint32_t k = 0;
  // Rows of k node indices, nearest first, padded with kNoNode: one row per node, then
  // one for the start position (row n). A node's own stroke partner is left out.
  std::vector<uint32_t> list;
  const uint32_t* row(uint32_t i) const { return list.data() + static_cast<size_t>(i) * k; }
};

// O(n k log n) with nanoflann's kd-tree; equally near nodes in its search order
// (deterministic).
Candidates nearest_candidates(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start, int k);

}  // namespace stipplot::plan::tour
