#include "methods/stipple/pds.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace stipplot::pds {

std::vector<uint32_t> random_order(size_t n, Rng& rng) {
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  for (size_t i = n; i > 1; --i) std::swap(order[i - 1], order[rng.below(static_cast<uint32_t>(i))]);
  return order;
}

std::vector<uint32_t> grayscale_order(const std::vector<uint8_t>& d, Rng& rng) {
  // Counting sort by level, then Fisher-Yates inside each level: the same law as
  // sorting by d + u with u ~ U[0,1), since u only breaks ties within a level.
  size_t start[257] = {0};
  for (uint8_t v : d) ++start[v + 1];
  for (int i = 0; i < 256; ++i) start[i + 1] += start[i];
  std::vector<uint32_t> order(d.size());
  size_t fill[256];
  std::copy(start, start + 256, fill);
  for (size_t i = 0; i < d.size(); ++i) order[fill[d[i]]++] = static_cast<uint32_t>(i);
  for (int level = 0; level < 256; ++level) {
    uint32_t* b = order.data() + start[level];
    size_t len = start[level + 1] - start[level];
    for (size_t i = len; i > 1; --i) std::swap(b[i - 1], b[rng.below(static_cast<uint32_t>(i))]);
  }
  return order;
}

DotGrid::DotGrid(int width, int height, double min_spacing) : w_(width), h_(height) {
  // Distinct pixels are at least 1 apart, so the spacing is never below 1.
  double s = std::max(1.0, min_spacing);
  g_ = std::clamp(static_cast<int>(std::lround(2 * s)), 2, 15);
  // Packing bound: discs of radius s/2 about the dots are disjoint and lie in a
  // square of side (g - 1 + s), so a cell holds at most (g-1+s)^2 / (pi s^2 / 4) dots.
  double bound = (g_ - 1 + s) * (g_ - 1 + s) / (M_PI * s * s / 4);
  cap_ = static_cast<int>(std::min<double>(g_ * g_, std::floor(bound)));
  gw_ = (w_ + g_ - 1) / g_;
  gh_ = (h_ + g_ - 1) / g_;
  count_.assign(static_cast<size_t>(gw_) * gh_, 0);
  slots_.assign(count_.size() * static_cast<size_t>(cap_), 0);
}

bool DotGrid::any_within(int x, int y, double r, double r2) const {
  const int ri = static_cast<int>(r);
  const int r2i = static_cast<int>(r2);  // integer squared distances: d2 <= r2 iff d2 <= floor(r2)
  const int x0 = std::max(0, x - ri), x1 = std::min(w_ - 1, x + ri);
  const int y0 = std::max(0, y - ri), y1 = std::min(h_ - 1, y + ri);
  const int cx0 = x0 / g_, cx1 = x1 / g_, cy0 = y0 / g_, cy1 = y1 / g_;
  for (int cy = cy0; cy <= cy1; ++cy) {
    const int by = cy * g_;
    const int dyn = y < by ? by - y : (y > by + g_ - 1 ? y - (by + g_ - 1) : 0);
    if (dyn * dyn > r2i) continue;
    const size_t row = static_cast<size_t>(cy) * gw_;
    for (int cx = cx0; cx <= cx1; ++cx) {
      const size_t c = row + static_cast<size_t>(cx);
      const int n = count_[c];
      if (n == 0) continue;
      const int bx = cx * g_;
      const int dxn = x < bx ? bx - x : (x > bx + g_ - 1 ? x - (bx + g_ - 1) : 0);
      if (dxn * dxn + dyn * dyn > r2i) continue;
      const uint8_t* s = &slots_[c * static_cast<size_t>(cap_)];
      for (int k = 0; k < n; ++k) {
        const int dx = bx + (s[k] & 15) - x, dy = by + (s[k] >> 4) - y;
        if (dx * dx + dy * dy <= r2i) return true;
      }
    }
  }
  return false;
}

void DotGrid::insert(int x, int y) {
  const size_t c = static_cast<size_t>(y / g_) * gw_ + static_cast<size_t>(x / g_);
  if (count_[c] >= cap_) throw std::logic_error("DotGrid: cell over its packing bound (dots closer than the spacing)");
  slots_[c * static_cast<size_t>(cap_) + count_[c]++] = static_cast<uint8_t>((x % g_) | ((y % g_) << 4));
}

RadiusTable RadiusTable::linear(double a, double b, bool inverted) {
  RadiusTable t;
  for (int v = 0; v < 256; ++v) {
    double d = inverted ? 255 - v : v;
    t.r[v] = a + b * d / 255.0;
    t.r2[v] = t.r[v] * t.r[v];
  }
  return t;
}

double RadiusTable::min() const { return *std::min_element(r, r + 256); }

std::vector<uint32_t> sample(int width, int height, const std::vector<uint8_t>& d, const RadiusTable& radius,
                             const std::vector<uint32_t>& order) {
  DotGrid grid(width, height, radius.min());
  std::vector<uint32_t> dots;
  const uint32_t w = static_cast<uint32_t>(width);
  for (uint32_t idx : order) {
    const int x = static_cast<int>(idx % w), y = static_cast<int>(idx / w);
    const uint8_t v = d[idx];
    if (!grid.any_within(x, y, radius.r[v], radius.r2[v])) {
      grid.insert(x, y);
      dots.push_back(idx);
    }
  }
  return dots;
}

BinaryResult sample_binary(int width, int height, const std::vector<uint8_t>& d, const RadiusTable& s,
                           const RadiusTable& t, const std::vector<uint32_t>& dark_first) {
  DotGrid black(width, height, s.min()), white(width, height, t.min());
  enum : uint8_t { kNone = 0, kBlack = 1, kWhite = 2 };
  std::vector<uint8_t> held(d.size(), kNone);
  BinaryResult out;
  const uint32_t w = static_cast<uint32_t>(width);
  const size_t n = dark_first.size();
  for (size_t k = 0; k < n; ++k) {
    // Step k: the k-th darkest pixel may take a black dot, then the k-th brightest a white one.
    uint32_t i = dark_first[k];
    if (held[i] != kWhite) {
      int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
      if (!black.any_within(x, y, s.r[d[i]], s.r2[d[i]])) {
        black.insert(x, y);
        held[i] = kBlack;
        out.black.push_back(i);
      }
    }
    uint32_t j = dark_first[n - 1 - k];
    if (held[j] != kBlack) {
      int x = static_cast<int>(j % w), y = static_cast<int>(j / w);
      if (!white.any_within(x, y, t.r[d[j]], t.r2[d[j]])) {
        white.insert(x, y);
        held[j] = kWhite;
        out.white.push_back(j);
      }
    }
  }
  return out;
}

}  // namespace stipplot::pds
