#pragma once
// Minimum spanning trees under the paper's anisotropic point distances (seed 002,
// SPEC.md §3): Euclidean (ED), bilateral (BD) and sign-inverted bilateral (SIBD).
//
//   ED   : sqrt(dx² + dy²)
//   BD   : sqrt(dx² + dy² + α (d_i − d_j)²)
//   SIBD : sqrt(dx² + dy² + α max(h − (d_i − d_j)², 0))
//
// Two exact algorithms: the paper's Prim on the complete graph (the O(n²)
// reference) and a Borůvka over a kd-tree that scales (see mst_exact).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "spatial/mst.hpp"

namespace stipplot::tree {

enum class Distance { ED, BD, SIBD };

struct CostParams {
  Distance kind = Distance::ED;
  double alpha = 1;  // weight of the intensity term (BD 1, SIBD 0.5 in the paper)
  double h = 300;    // SIBD threshold on the squared intensity difference
  void validate() const;  // UserError naming --alpha / --h
};

// Points with an intensity d each (grey levels for BD/SIBD, scaled edge distance
// for the cross variants). Coordinates in pixels.
struct PointSet {
  std::vector<float> x, y, d;
  size_t size() const { return x.size(); }
  void push(float px, float py, float pd) {
    x.push_back(px);
    y.push_back(py);
    d.push_back(pd);
  }
};

using Edge = spatial::Edge;

// The squared distance between points i and j; both MST algorithms use exactly this.
double edge_cost2(const PointSet& p, const CostParams& c, uint32_t i, uint32_t j);

// The paper's Prim on the complete graph. O(n²) time, O(n) memory. Reference only.
std::vector<Edge> mst_prim_reference(const PointSet& p, const CostParams& c);

// Exact MST by spatial::boruvka_mst over a kd-tree in (x, y, d), with box lower bounds
// of each cost: spatial distance, plus for BD the intensity gap, for SIBD the least
// possible penalty. Time O(n log n) to build plus O(log n) rounds of near-logarithmic
// queries on well-spread points (stipples); memory O(n).
using MstStats = spatial::MstStats;
std::vector<Edge> mst_exact(const PointSet& p, const CostParams& c, MstStats* stats = nullptr);

using spatial::total_cost;

Distance parse_distance(const std::string& name);  // "ed" | "bd" | "sibd"
const char* to_string(Distance d);

}  // namespace stipplot::tree
