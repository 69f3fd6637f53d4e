#include "eval/mark_spacing.hpp"

#include <cmath>

#include "spatial/knn.hpp"

namespace stipplot {

double mark_spacing(const std::vector<Vec2>& marks) {
  if (marks.size() < 2) return 0;
  const spatial::PlaneKnn knn(marks, marks.size());
  double s2 = 0, s3 = 0;
  uint32_t idx[2];
  double d2[2];
  for (const Vec2& m : marks) {
    // The nearest is the mark itself (or a twin at the same place, which counts as 0).
    if (knn.k_nearest(m, 2, idx, d2) < 2) continue;
    const double d = std::sqrt(d2[1]);
    s2 += d * d, s3 += d * d * d;
  }
  return s2 > 0 ? s3 / s2 : 0;
}

}  // namespace stipplot
