#include "spatial/knn.hpp"

#include <algorithm>
#include <nanoflann.hpp>

namespace stipplot::spatial {

namespace {
// The distinct positions, as nanoflann wants them.
struct PointCloud {
  std::vector<Vec2> pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
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
  // Input indices grouped by position: those of distinct position j are
  // ids[first[j] .. first[j + 1]), ascending; positions in the order of their lowest index.
  std::vector<uint32_t> ids, first;
  NanoTree tree;
  explicit Index(PointCloud c) : cloud(std::move(c)), tree(2, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}
};

namespace {
// nanoflann opens every box at the best distance so far, so a query among m coincident
// points costs O(m): indexing each position once keeps heavy duplicates O(log n). The
// positions keep the order of their lowest index, so a caller's spatially sorted points
// stay sorted for nanoflann (its searches are a quarter slower on an x-sorted cloud).
PointCloud distinct_positions(const std::vector<Vec2>& pts, size_t n, std::vector<uint32_t>& ids,
                              std::vector<uint32_t>& first) {
  struct Item {
    Vec2 p;
    uint32_t id;
  };
  std::vector<Item> items(n);
  for (uint32_t i = 0; i < n; ++i) items[i] = {pts[i], i};
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    return a.p.x != b.p.x ? a.p.x < b.p.x : a.p.y != b.p.y ? a.p.y < b.p.y : a.id < b.id;
  });
  // Each group of coincident points, found in sorted order, by its lowest index.
  constexpr uint32_t kNone = UINT32_MAX;
  std::vector<uint32_t> group_start(n, kNone);
  for (uint32_t k = 0; k < n; ++k)
    if (k == 0 || !(items[k].p == items[k - 1].p)) group_start[items[k].id] = k;
  PointCloud c;
  ids.reserve(n);
  for (uint32_t lowest = 0; lowest < n; ++lowest) {
    const uint32_t k0 = group_start[lowest];
    if (k0 == kNone) continue;
    first.push_back(static_cast<uint32_t>(ids.size()));
    c.pts.push_back(items[k0].p);
    for (uint32_t k = k0; k < n && items[k].p == items[k0].p; ++k) ids.push_back(items[k].id);
  }
  first.push_back(static_cast<uint32_t>(n));
  return c;
}
}  // namespace

PlaneKnn::PlaneKnn(const std::vector<Vec2>& pts, size_t n) {
  std::vector<uint32_t> ids, first;
  PointCloud c = distinct_positions(pts, n, ids, first);
  index_ = std::make_unique<Index>(std::move(c));
  index_->ids = std::move(ids);
  index_->first = std::move(first);
}
PlaneKnn::~PlaneKnn() = default;

size_t PlaneKnn::k_nearest(Vec2 q, size_t k, uint32_t* out, double* dist2) const {
  const Index& ix = *index_;
  if (k == 0 || ix.cloud.pts.empty()) return 0;
  // k positions hold at least k points.
  constexpr size_t kOnStack = 64;
  uint32_t pos_buf[kOnStack];
  double d_buf[kOnStack];
  std::vector<uint32_t> pos_big;
  std::vector<double> d_big;
  if (k > kOnStack) pos_big.resize(k), d_big.resize(k);
  uint32_t* pos = k > kOnStack ? pos_big.data() : pos_buf;
  double* d = k > kOnStack ? d_big.data() : d_buf;
  const double at[2] = {q.x, q.y};
  const size_t found = ix.tree.knnSearch(at, k, pos, d);
  size_t got = 0;
  for (size_t j = 0; j < found && got < k; ++j)
    for (uint32_t m = ix.first[pos[j]]; m < ix.first[pos[j] + 1] && got < k; ++m) {
      out[got] = ix.ids[m];
      dist2[got++] = d[j];
    }
  return got;
}

}  // namespace stipplot::spatial
