#pragma once
// An even share of a list: item i is kept when frac(i / phi) < share. frac(i / phi) is
// equidistributed with low discrepancy, so the kept items are spread evenly over the
// list, and over the page too when the list runs across it. O(1) an item.
#include <cmath>
#include <cstddef>

namespace stipplot {

inline bool in_even_share(size_t i, double share) {
  constexpr double inv_phi = 0.6180339887498949;
  const double u = static_cast<double>(i) * inv_phi;
  return u - std::floor(u) < share;
}

}  // namespace stipplot
