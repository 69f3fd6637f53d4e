#include "spatial/knn.hpp"

#include <nanoflann.hpp>

namespace stipplot::spatial {

namespace {
// The first n points of a vector, as nanoflann wants them.
struct PointCloud {
  const std::vector<Vec2>& pts;
  size_t n;
  size_t kdtree_get_point_count() const { return n; }
  double kdtree_get_pt(size_t i, size_t dim) const { return dim == 0 ? pts[i].x : pts[i].y; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};
using NanoTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloud>, PointCloud, 2,
                                                     uint32_t>;
}  // namespace

struct PlaneKnn::Index {
  PointCloud cloud;
  NanoTree tree;
  Index(const std::vector<Vec2>& pts, size_t n)
      : cloud{pts, n}, tree(2, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}
};

PlaneKnn::PlaneKnn(const std::vector<Vec2>& pts, size_t n) : index_(std::make_unique<Index>(pts, n)) {}
PlaneKnn::~PlaneKnn() = default;

size_t PlaneKnn::k_nearest(Vec2 q, size_t k, uint32_t* out, double* dist2) const {
  if (k == 0 || index_->cloud.n == 0) return 0;
  const double at[2] = {q.x, q.y};
  return index_->tree.knnSearch(at, k, out, dist2);
}

}  // namespace stipplot::spatial
