#pragma once
// Open travelling-salesman paths over pen positions: the order in which a layer's
// dots and strokes are drawn. A node is a point the pen must visit; a stroke is two
// nodes (its ends) that must stay adjacent in the path, so the path may draw it in
// either direction.
#include <cstdint>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::plan {

struct TourOptions {
  double seconds = 1.0;   // improvement budget; 0 = greedy construction only
  int neighbors = 10;     // candidate list size for 2-opt / Or-opt
};

struct TourStats {
  double construct_seconds = 0, improve_seconds = 0;
  long moves_2opt = 0, moves_oropt = 0;
  bool budget_hit = false;  // false: stopped at a local optimum (deterministic)
};

// Returns every node exactly once, the path starting nearest `start`, with each
// node i that has partner[i] >= 0 next to its partner (partner must be symmetric).
// Construction: greedy nearest neighbour over a kd-tree with deletion, O(n log n).
// Improvement: 2-opt and Or-opt (segments of 1-3 nodes, either orientation) over
// k-nearest-neighbour candidate lists with a work queue, on an array tour that
// reverses the shorter side: O(k) per node visit plus the reversal lengths, run to
// a local optimum or until the time budget.
std::vector<uint32_t> plan_tour(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                                const TourOptions& opt, TourStats* stats = nullptr);

// Pen-up length of visiting `order` from `start` (partners' joining edges excluded).
double tour_travel(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                   const std::vector<uint32_t>& order);

}  // namespace stipplot::plan
