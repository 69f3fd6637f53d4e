#include "spatial/mst.hpp"

namespace stipplot::spatial {

std::vector<Edge> euclidean_mst(const std::vector<Vec2>& pts, MstStats* stats) {
  return boruvka_mst(plane_tree(pts), EuclideanCost<2, double>{}, stats);
}

double total_cost(const std::vector<Edge>& edges) {
  double s = 0;
  for (const Edge& e : edges) s += e.cost;
  return s;
}

}  // namespace stipplot::spatial
