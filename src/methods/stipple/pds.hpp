#pragma once
// Poisson disk sampling over a per-pixel radius field (seed 000, SPEC.md §1).
// The building block of every stippling variant and of the tree method's points.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "util/rng.hpp"

namespace stipplot::pds {

// Progress callback: fraction of the work done, called about every million pixels.
using ProgressFn = std::function<void(double)>;

// Visiting orders. Both return pixel indices (y * width + x).
// Random order: a uniform permutation. O(n).
std::vector<uint32_t> random_order(size_t n, Rng& rng);
// Grayscale order: increasing f = d + u, u ~ U[0,1): darkest first, ties at random.
// Counting sort on d with a random shuffle inside each level is exactly this
// ordering, in O(n) instead of a comparison sort's O(n log n).
std::vector<uint32_t> grayscale_order(const std::vector<uint8_t>& d, Rng& rng);

// Uniform grid of dots answering "is there a dot within r of (x, y)?" by looking only
// at the cells the disc's bounding box overlaps. Cell size g is chosen from the
// minimum dot spacing so a cell holds a small fixed number of dots (a packing bound).
class DotGrid {
 public:
  // min_spacing: every two dots are more than this apart (the smallest radius).
  DotGrid(int width, int height, double min_spacing);
  // True if some dot p has |p - (x,y)|^2 <= r2. O((r/g + 2)^2 * capacity).
  bool any_within(int x, int y, double r, double r2) const;
  void insert(int x, int y);
  int cell_size() const { return g_; }
  int capacity() const { return cap_; }

 private:
  int w_, h_, g_, gw_, gh_, cap_;
  int stride_;  // bytes a cell: a count then cap_ slots, padded to a power of two
  // Cell c lives at cells_[c * stride_]: [count, slot0, slot1, ...]; a slot packs the
  // dot's offset inside the cell as dx | dy << 4. One cache line holds several cells.
  std::vector<uint8_t> cells_;
};

// Pixels certainly blocked, as a bit per pixel. Valid when radii never decrease along
// the visiting order (grayscale order: r grows with d): a pixel within r_p of an earlier
// dot p is within its own r >= r_p of it. Painting each dot's disc once costs
// O(dots * r^2) = O(n) in all, and spares most pixels the grid query.
class CoverMask {
 public:
  CoverMask(int width, int height);
  bool covered(size_t idx) const { return (bits_[idx >> 6] >> (idx & 63)) & 1; }
  void prefetch(size_t idx) const { __builtin_prefetch(&bits_[idx >> 6]); }
  void paint_disc(int x, int y, double r2);

 private:
  void set_span(size_t from, size_t to);  // inclusive pixel indices in one row
  int w_, h_;
  std::vector<uint64_t> bits_;
};

// Radius lookup by grey level: r(d) for d = 0..255. An infinite radius means a pixel of
// that level never gets a dot (tones too light to draw).
struct RadiusTable {
  double r[256];
  double r2[256];
  static RadiusTable linear(double a, double b, bool inverted);  // a + b*d/255 or a + b*(255-d)/255
  // Lines through points this far apart lay ink in proportion to the darkness t = 1 - d/255:
  // r = a / t, as far as a + b; lighter levels get no point.
  static RadiusTable tone(double a, double b);
  double min() const;  // the smallest finite radius (infinity if none)
  bool none(uint8_t v) const { return !(r[v] < 1e300); }
};

// Poisson disk sampling: visit pixels in `order`; a pixel gets a dot unless a dot
// already placed lies within its radius (closed disc). Returns dot pixel indices in
// placement order. O(n * (r_max/g + 2)^2 * capacity) time, O(n) memory.
std::vector<uint32_t> sample(int width, int height, const std::vector<uint8_t>& d, const RadiusTable& radius,
                             const std::vector<uint32_t>& order, const ProgressFn& progress = {});

// Binary stippling: black dots visited dark first with radius s, white dots bright
// first with radius t, interleaved step by step; a pixel never holds both colours.
struct BinaryResult {
  std::vector<uint32_t> black, white;
};
BinaryResult sample_binary(int width, int height, const std::vector<uint8_t>& d, const RadiusTable& s,
                           const RadiusTable& t, const std::vector<uint32_t>& dark_first,
                           const ProgressFn& progress = {});

}  // namespace stipplot::pds
