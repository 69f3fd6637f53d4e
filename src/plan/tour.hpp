#pragma once
// Open travelling-salesman paths over pen positions: the order in which a layer's
// dots and strokes are drawn. A node is a point the pen must visit; a stroke is two
// nodes (its ends) that must stay adjacent in the path, so the path may draw it in
// either direction.
#include <cstdint>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::plan {

enum class TourStart { GreedyEdge, NearestNeighbour };

struct TourOptions {
  TourStart start = TourStart::GreedyEdge;
  bool improve = true;          // 2-opt/Or-opt to a local optimum (false: construction only)
  // The work budget after the local optimum: perturbation trials. Work, not time, so
  // the same nodes and options give the same path on any machine at any load.
  long kicks = 0;
  // Wall-clock cap on the improvement: when it trips, the path is the best found so
  // far, no longer reproducible. 0 = construction only.
  double seconds_cap = 60;
  int neighbors = 10;           // candidate list size
  uint64_t seed = 1;            // of the perturbations
};

struct TourStats {
  double construct_seconds = 0, improve_seconds = 0;
  long moves_2opt = 0, moves_oropt = 0;
  long kicks = 0, kicks_kept = 0;  // perturbations made, and kept for shortening the path
  long long reversed = 0;          // array elements moved by reversals (the main cost)
  double gain = 0;                 // travel the improvement saved, as its moves reckon it
  bool capped = false;             // the wall-clock cap stopped the improvement
};

// Returns every node exactly once, the path starting nearest `start`, with each
// node i that has partner[i] >= 0 next to its partner (partner must be symmetric).
// Nodes are first renumbered in kd-tree order (O(n log n)) so that near nodes are near
// in memory. Candidates: k nearest neighbours, O(n k log n). Construction: greedy edge
// matching, O(n k log(n k)), or greedy nearest neighbour, O(n log n). Improvement:
// 2-opt and Or-opt with a work queue (don't-look bits) on an array that reverses the
// shorter side, to a local optimum: O(k) per examined node plus the reversals, in
// practice O(n) examinations; then `kicks` segment-swap perturbations, each O(segment +
// the local search it triggers, whose reversals are capped) and undone unless it helps.
std::vector<uint32_t> plan_tour(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                                const TourOptions& opt, TourStats* stats = nullptr);
// The same path from points given up: a path split in halves frees them once the halves
// hold their copies (1M nodes: 16 MB less while both halves are built).
std::vector<uint32_t> plan_tour(std::vector<Vec2>&& pts, const std::vector<int32_t>& partner, Vec2 start,
                                const TourOptions& opt, TourStats* stats = nullptr);

// Pen-up length of visiting `order` from `start` (partners' joining edges excluded).
double tour_travel(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                   const std::vector<uint32_t>& order);

}  // namespace stipplot::plan
