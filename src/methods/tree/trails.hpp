#pragma once
// A forest of segments drawn as few pen-down trails. A tree's edges are segments between
// points; drawn one by one, every edge is a stroke and costs a pen lift (0.3 s on a servo
// plotter: most of an hour of a dense tree). An Euler trail through a tree cannot avoid a
// stroke end at every odd-degree point, but drawing an edge a second time (back along it,
// pen down) flips both its ends' parity: where retracing is cheaper than the lift it saves,
// the pen stays down. The choice of which edges to retrace is exact (a tree DP over vertex
// parity), then Hierholzer's algorithm walks the trails.
#include <cstdint>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::tree {

struct TrailEdge {
  uint32_t a = 0, b = 0;  // vertex indices
};

struct TrailPlan {
  std::vector<std::vector<uint32_t>> trails;  // vertex sequences; each a pen-down stroke
  size_t retraced_edges = 0;                  // edges drawn twice
  double retraced_length = 0;                 // their length (units of the positions)
};

// Trails covering every edge of the forest (vertices `pos`, edges `edges`; should they
// form a cycle, its closing edge is drawn once and left out of the choice) at least once
// and at most twice, minimising
//   retraced length + lift_length x (number of trails)
// exactly: each trail's start costs `lift_length` (the line as long as a pen lift takes).
// lift_length 0 retraces nothing (the fewest trails an Euler decomposition allows).
// O(V + E).
TrailPlan forest_trails(const std::vector<Vec2>& pos, const std::vector<TrailEdge>& edges, double lift_length);

}  // namespace stipplot::tree

namespace stipplot::tree {

// A forest drawn with a heavier line: each tree is one closed pen-down loop around it,
// `offset` to either side of its edges (the walk round a tree's one face: at every point
// the next edge turning from the one it came by, so every edge is passed once on each
// side). With offset = half a pen width the two passes touch: a line two pens wide, and
// no pen lift inside a tree. Outer corners are rounded by arcs of radius `offset` (a
// branch's tip a half circle), inner ones mitred; then every corner of the loop is cut
// `rounds` times (Chaikin: a corner replaced by the points a quarter of the way along its
// two sides; two rounds give a smooth quadratic B-spline). A plotter must nearly stop at
// a sharp corner (grbl-servo: about 5 mm/s at 90 degrees); the smoothed loop of a tree
// of 1 mm edges is drawn about a third faster, at the cost of the corners' last tenth of
// a millimetre. Vertices without edges give nothing; should the edges form a cycle,
// each of its faces' walks is a loop of its own. O((V + E log(degree)) 2^rounds).
inline constexpr int kOutlineRounds = 2;
std::vector<Polyline> forest_outlines(const std::vector<Vec2>& pos, const std::vector<TrailEdge>& edges, double offset,
                                      int rounds = kOutlineRounds);

}  // namespace stipplot::tree
