#include "candidates.hpp"

#include <algorithm>

#include "spatial/knn.hpp"
#include "util/threads.hpp"

namespace stipplot::plan::tour {

Candidates nearest_candidates(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start, int k) {
  const uint32_t n = static_cast<uint32_t>(pts.size());
  Candidates c;
  c.k = static_cast<uint32_t>(std::max(1, k));
  c.list.assign(static_cast<size_t>(n + 1) * c.k, kNoNode);
  if (n == 0) return c;
  const spatial::PlaneKnn knn(pts, n);
  // Each node's row on its own: rows in parallel, the same list on any thread count
  // (below ~2,000 nodes a thread costs more than it saves).
  const int64_t rows = static_cast<int64_t>(n) + 1;
#pragma omp parallel num_threads(thread_count()) if (rows >= 2'000)
  {
    // Two more than k: the node itself and its partner are dropped.
    std::vector<uint32_t> idx(c.k + 2);
    std::vector<double> d2(c.k + 2);
#pragma omp for schedule(static, 4096)
    for (int64_t r = 0; r < rows; ++r) {
      const uint32_t i = static_cast<uint32_t>(r);
      const size_t got = knn.k_nearest(i < n ? pts[i] : start, c.k + 2, idx.data(), d2.data());
      uint32_t* row = c.list.data() + static_cast<size_t>(i) * c.k;
      uint32_t m = 0;
      for (size_t j = 0; j < got && m < c.k; ++j) {
        if (i < n && (idx[j] == i || partner[i] == static_cast<int32_t>(idx[j]))) continue;
        row[m++] = idx[j];
      }
    }
  }
  return c;
}

}  // namespace stipplot::plan::tour
