#include "methods/stipple/pds.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "util/threads.hpp"

namespace stipplot::pds {

std::vector<uint32_t> random_order(size_t n, Rng& rng) {
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  for (size_t i = n; i > 1; --i) std::swap(order[i - 1], order[rng.below(static_cast<uint32_t>(i))]);
  return order;
}

std::vector<uint32_t> grayscale_order(const std::vector<uint8_t>& d, Rng& rng) {
  // Counting sort by level, then Fisher-Yates inside each level: the same law as
  // sorting by d + u with u ~ U[0,1), since u only breaks ties within a level. One
  // random stream, level after level (a level of n pixels takes n - 1 draws).
  // On threads from a million pixels, the same order bit for bit: the sort stable by
  // blocks of pixels (each block's share of a level placed after the earlier blocks'),
  // and the levels shuffled in groups, each group from the stream's state where the
  // levels before it leave it (found by running the stream on: ~1 ns a draw).
  const size_t n = d.size();
  const int parts = n >= (size_t{1} << 20) && !in_parallel_part() ? std::max(1, thread_count()) : 1;
  std::vector<std::array<size_t, 256>> count(static_cast<size_t>(parts));
  auto block = [&](int t) { return std::pair{n * static_cast<size_t>(t) / static_cast<size_t>(parts), n * static_cast<size_t>(t + 1) / static_cast<size_t>(parts)}; };
#pragma omp parallel for num_threads(parts) schedule(static, 1) if (parts > 1)
  for (int t = 0; t < parts; ++t) {
    auto& c = count[static_cast<size_t>(t)];
    c.fill(0);
    const auto [from, to] = block(t);
    for (size_t i = from; i < to; ++i) ++c[d[i]];
  }
  size_t start[257] = {0};
  for (int v = 0; v < 256; ++v) {
    start[v + 1] = start[v];
    for (int t = 0; t < parts; ++t) start[v + 1] += count[static_cast<size_t>(t)][static_cast<size_t>(v)];
  }
  // Each block's first slot in each level.
  std::vector<std::array<size_t, 256>> fill(static_cast<size_t>(parts));
  for (int v = 0; v < 256; ++v) {
    size_t at = start[v];
    for (int t = 0; t < parts; ++t) {
      fill[static_cast<size_t>(t)][static_cast<size_t>(v)] = at;
      at += count[static_cast<size_t>(t)][static_cast<size_t>(v)];
    }
  }
  std::vector<uint32_t> order(n);
#pragma omp parallel for num_threads(parts) schedule(static, 1) if (parts > 1)
  for (int t = 0; t < parts; ++t) {
    auto& f = fill[static_cast<size_t>(t)];
    const auto [from, to] = block(t);
    for (size_t i = from; i < to; ++i) order[f[d[i]]++] = static_cast<uint32_t>(i);
  }
  // Groups of levels of about n / parts pixels each, each from the stream's state where
  // the levels before it leave it.
  std::vector<int> first_level{0};
  for (int level = 0; level < 256; ++level)
    if (first_level.size() < static_cast<size_t>(parts) && start[level + 1] >= n * first_level.size() / static_cast<size_t>(parts))
      first_level.push_back(level + 1);
  first_level.push_back(256);
  const int groups = static_cast<int>(first_level.size()) - 1;
  std::vector<Rng> stream(static_cast<size_t>(groups), rng);
  for (int g = 1; g < groups; ++g) {
    Rng& r = stream[static_cast<size_t>(g)] = stream[static_cast<size_t>(g) - 1];
    for (int level = first_level[static_cast<size_t>(g) - 1]; level < first_level[static_cast<size_t>(g)]; ++level)
      for (size_t i = start[level + 1] - start[level]; i > 1; --i) r.next();
  }
#pragma omp parallel for num_threads(parts) schedule(static, 1) if (parts > 1)
  for (int g = 0; g < groups; ++g) {
    Rng& r = stream[static_cast<size_t>(g)];
    for (int level = first_level[static_cast<size_t>(g)]; level < first_level[static_cast<size_t>(g) + 1]; ++level) {
      uint32_t* b = order.data() + start[level];
      const size_t len = start[level + 1] - start[level];
      for (size_t i = len; i > 1; --i) std::swap(b[i - 1], b[r.below(static_cast<uint32_t>(i))]);
    }
  }
  rng = stream.back();  // where the last level's draws leave the stream
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
  stride_ = 1;
  while (stride_ < cap_ + 1) stride_ *= 2;
  cells_.assign(static_cast<size_t>(gw_) * gh_ * stride_, 0);
}

bool DotGrid::any_within(int x, int y, double r, double r2) const {
  const int ri = static_cast<int>(r);
  const int r2i = static_cast<int>(r2);  // integer squared distances: d2 <= r2 iff d2 <= floor(r2)
  const int gx = x / g_, gy = y / g_;
  // The pixel's own cell first: a blocking dot is most often there.
  auto check = [&](int cx, int cy) {
    const uint8_t* c = &cells_[(static_cast<size_t>(cy) * gw_ + static_cast<size_t>(cx)) * stride_];
    const int n = c[0];
    const int bx = cx * g_ - x, by = cy * g_ - y;
    for (int k = 1; k <= n; ++k) {
      const int dx = bx + (c[k] & 15), dy = by + (c[k] >> 4);
      if (dx * dx + dy * dy <= r2i) return true;
    }
    return false;
  };
  if (check(gx, gy)) return true;
  const int cx0 = std::max(0, x - ri) / g_, cx1 = std::min(w_ - 1, x + ri) / g_;
  const int cy0 = std::max(0, y - ri) / g_, cy1 = std::min(h_ - 1, y + ri) / g_;
  for (int cy = cy0; cy <= cy1; ++cy) {
    const int by = cy * g_;
    const int dyn = y < by ? by - y : (y > by + g_ - 1 ? y - (by + g_ - 1) : 0);
    if (dyn * dyn > r2i) continue;
    for (int cx = cx0; cx <= cx1; ++cx) {
      if (cx == gx && cy == gy) continue;
      const int bx = cx * g_;
      const int dxn = x < bx ? bx - x : (x > bx + g_ - 1 ? x - (bx + g_ - 1) : 0);
      if (dxn * dxn + dyn * dyn > r2i) continue;
      if (check(cx, cy)) return true;
    }
  }
  return false;
}

void DotGrid::insert(int x, int y) {
  uint8_t* c = &cells_[(static_cast<size_t>(y / g_) * gw_ + static_cast<size_t>(x / g_)) * stride_];
  if (c[0] >= cap_) throw std::logic_error("DotGrid: cell over its packing bound (dots closer than the spacing)");
  c[1 + c[0]++] = static_cast<uint8_t>((x % g_) | ((y % g_) << 4));
}

CoverMask::CoverMask(int width, int height)
    : w_(width), h_(height), bits_((static_cast<size_t>(width) * height + 63) / 64, 0) {}

void CoverMask::set_span(size_t from, size_t to) {
  size_t wa = from >> 6, wb = to >> 6;
  uint64_t ma = ~0ull << (from & 63), mb = ~0ull >> (63 - (to & 63));
  if (wa == wb) {
    bits_[wa] |= ma & mb;
    return;
  }
  bits_[wa] |= ma;
  for (size_t k = wa + 1; k < wb; ++k) bits_[k] = ~0ull;
  bits_[wb] |= mb;
}

void CoverMask::paint_disc(int x, int y, double r2) {
  const int ri = static_cast<int>(std::sqrt(r2));
  const int r2i = static_cast<int>(r2);
  for (int dy = -ri; dy <= ri; ++dy) {
    const int yy = y + dy;
    if (yy < 0 || yy >= h_) continue;
    int hw = static_cast<int>(std::sqrt(static_cast<double>(r2i - dy * dy)));
    while ((hw + 1) * (hw + 1) + dy * dy <= r2i) ++hw;  // exact integer half-width
    while (hw > 0 && hw * hw + dy * dy > r2i) --hw;
    const int xa = std::max(0, x - hw), xb = std::min(w_ - 1, x + hw);
    const size_t row = static_cast<size_t>(yy) * static_cast<size_t>(w_);
    set_span(row + static_cast<size_t>(xa), row + static_cast<size_t>(xb));
  }
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

RadiusTable RadiusTable::tone(double a, double b) {
  RadiusTable t;
  for (int v = 0; v < 256; ++v) {
    const double dark = 1 - v / 255.0;
    double r = dark > 0 ? a / dark : std::numeric_limits<double>::infinity();
    if (!(r <= a + b)) r = std::numeric_limits<double>::infinity();
    t.r[v] = r;
    t.r2[v] = r * r;
  }
  return t;
}

double RadiusTable::min() const {
  double m = std::numeric_limits<double>::infinity();
  for (double v : r)
    if (v < m) m = v;
  return m;
}

namespace {
constexpr size_t kProgressMask = (1u << 20) - 1;

// True when the radius never decreases along the order, so CoverMask applies (pixels
// that never get a dot do not count).
bool radii_monotone(const std::vector<uint8_t>& d, const RadiusTable& radius, const std::vector<uint32_t>& order) {
  double last = -1;
  for (uint32_t idx : order) {
    double r = radius.r[d[idx]];
    if (radius.none(d[idx])) continue;
    if (r < last) return false;
    last = r;
  }
  return true;
}
}  // namespace

std::vector<uint32_t> sample(int width, int height, const std::vector<uint8_t>& d, const RadiusTable& radius,
                             const std::vector<uint32_t>& order, const ProgressFn& progress) {
  std::vector<uint32_t> dots;
  if (!std::isfinite(radius.min())) return dots;
  DotGrid grid(width, height, radius.min());
  const uint32_t w = static_cast<uint32_t>(width);
  if (radii_monotone(d, radius, order)) {
    CoverMask cover(width, height);
    // The order jumps about the image: each pixel's level and cover bit are a cache miss
    // unless asked for this many pixels ahead (the same result; BM_GrayscalePDS, order and
    // sampling, 261-267 -> 154-236 ms on this VM).
    constexpr size_t kAhead = 64;
    for (size_t k = 0; k < order.size(); ++k) {
      if (progress && (k & kProgressMask) == 0) progress(static_cast<double>(k) / static_cast<double>(order.size()));
      if (k + kAhead < order.size()) {
        __builtin_prefetch(&d[order[k + kAhead]]);
        cover.prefetch(order[k + kAhead]);
      }
      const uint32_t idx = order[k];
      if (cover.covered(idx) || radius.none(d[idx])) continue;
      const int x = static_cast<int>(idx % w), y = static_cast<int>(idx / w);
      const uint8_t v = d[idx];
      if (!grid.any_within(x, y, radius.r[v], radius.r2[v])) {
        grid.insert(x, y);
        cover.paint_disc(x, y, radius.r2[v]);
        dots.push_back(idx);
      }
    }
    return dots;
  }
  for (size_t k = 0; k < order.size(); ++k) {
    if (progress && (k & kProgressMask) == 0) progress(static_cast<double>(k) / static_cast<double>(order.size()));
    const uint32_t idx = order[k];
    if (radius.none(d[idx])) continue;
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
                           const RadiusTable& t, const std::vector<uint32_t>& dark_first,
                           const ProgressFn& progress) {
  // A colour that never gets a dot still needs a (never queried) grid.
  auto spacing = [](const RadiusTable& r) { return std::isfinite(r.min()) ? r.min() : 1.0; };
  DotGrid black(width, height, spacing(s)), white(width, height, spacing(t));
  // Black radii grow along the dark-first order and white radii along its reverse
  // whenever s and t are the paper's linear ramps; otherwise the masks stay unused.
  const bool black_mono = radii_monotone(d, s, dark_first);
  const std::vector<uint32_t> bright_first(dark_first.rbegin(), dark_first.rend());
  const bool white_mono = radii_monotone(d, t, bright_first);
  CoverMask black_cover(black_mono ? width : 0, black_mono ? height : 0);
  CoverMask white_cover(white_mono ? width : 0, white_mono ? height : 0);
  enum : uint8_t { kNone = 0, kBlack = 1, kWhite = 2 };
  std::vector<uint8_t> held(d.size(), kNone);
  BinaryResult out;
  const uint32_t w = static_cast<uint32_t>(width);
  // One colour's step: pixel i takes a dot unless it holds the other colour or a dot of
  // this colour lies within its radius.
  auto place = [&](uint32_t i, uint8_t mine, uint8_t other, DotGrid& grid, CoverMask& cover, bool mono,
                   const RadiusTable& r, std::vector<uint32_t>& dots) {
    if (held[i] == other || r.none(d[i]) || (mono && cover.covered(i))) return;
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    if (grid.any_within(x, y, r.r[d[i]], r.r2[d[i]])) return;
    grid.insert(x, y);
    if (mono) cover.paint_disc(x, y, r.r2[d[i]]);
    held[i] = mine;
    dots.push_back(i);
  };
  const size_t n = dark_first.size();
  for (size_t k = 0; k < n; ++k) {
    if (progress && (k & kProgressMask) == 0) progress(static_cast<double>(k) / static_cast<double>(n));
    // Step k: the k-th darkest pixel may take a black dot, then the k-th brightest a white one.
    place(dark_first[k], kBlack, kWhite, black, black_cover, black_mono, s, out.black);
    place(bright_first[k], kWhite, kBlack, white, white_cover, white_mono, t, out.white);
  }
  return out;
}

}  // namespace stipplot::pds
