#pragma once
// k nearest neighbours in the plane for a fixed set of points: the planner's 2-opt /
// Or-opt candidate lists. nanoflann (the Debian package) does the searching; its
// headers stay inside this library.
#include <cstdint>
#include <memory>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::spatial {

class PlaneKnn {
 public:
  // Indexes pts[0, n) (copied: each distinct position once). O(n log n).
  PlaneKnn(const std::vector<Vec2>& pts, size_t n);
  ~PlaneKnn();
  PlaneKnn(const PlaneKnn&) = delete;
  PlaneKnn& operator=(const PlaneKnn&) = delete;
  // Writes the indices of the k indexed points nearest q, nearest first, and their
  // squared distances into out[0, k) and dist2[0, k); returns how many (fewer when
  // fewer points are indexed). Equally near points at different positions come in
  // nanoflann's search order, coincident points by index: the plans' tie-breaking
  // depends on both. O(k log n), however many points coincide.
  size_t k_nearest(Vec2 q, size_t k, uint32_t* out, double* dist2) const;

 private:
  struct Index;
  std::unique_ptr<Index> index_;
};

}  // namespace stipplot::spatial
