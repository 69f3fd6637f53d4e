#include <catch2/catch.hpp>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "methods/stipple/pds.hpp"
#include "methods/stipple/stipple.hpp"
#include "util/rng.hpp"
#include "util/threads.hpp"

using namespace stipplot;

namespace {

// The relaxation as one plain pass over the dots and one over the cells: what the banded,
// parallel relax_points must equal bit for bit.
void relax_serial(std::vector<Vec2>& pts, const std::vector<uint8_t>& plane, const pds::RadiusTable& radius, int w,
                  int h, int iterations) {
  const size_t n = static_cast<size_t>(w) * h;
  std::array<double, 256> weight{};
  for (int v = 0; v < 256; ++v) weight[v] = radius.none(static_cast<uint8_t>(v)) ? 0 : 1 / std::pow(radius.r[v], 4);
  std::vector<float> best(n);
  std::vector<uint32_t> owner(n);
  std::vector<double> sx(pts.size()), sy(pts.size()), sw(pts.size());
  for (int it = 0; it < iterations; ++it) {
    std::fill(best.begin(), best.end(), std::numeric_limits<float>::infinity());
    for (uint32_t k = 0; k < pts.size(); ++k) {
      const int cx = std::clamp(static_cast<int>(pts[k].x), 0, w - 1), cy = std::clamp(static_cast<int>(pts[k].y), 0, h - 1);
      const uint8_t v = plane[static_cast<size_t>(cy) * w + cx];
      const double reach = 1.5 * (radius.none(v) ? radius.min() : radius.r[v]);
      const int x0 = std::max(0, static_cast<int>(pts[k].x - reach)), x1 = std::min(w - 1, static_cast<int>(pts[k].x + reach));
      const int y0 = std::max(0, static_cast<int>(pts[k].y - reach)), y1 = std::min(h - 1, static_cast<int>(pts[k].y + reach));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const double dx = x + 0.5 - pts[k].x, dy = y + 0.5 - pts[k].y;
          const float d2 = static_cast<float>(dx * dx + dy * dy);
          const size_t i = static_cast<size_t>(y) * w + x;
          if (d2 < best[i]) best[i] = d2, owner[i] = k;
        }
    }
    std::fill(sx.begin(), sx.end(), 0.0);
    std::fill(sy.begin(), sy.end(), 0.0);
    std::fill(sw.begin(), sw.end(), 0.0);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        if (!std::isfinite(best[i])) continue;
        const double wt = weight[plane[i]];
        sx[owner[i]] += wt * (x + 0.5), sy[owner[i]] += wt * (y + 0.5), sw[owner[i]] += wt;
      }
    for (size_t k = 0; k < pts.size(); ++k)
      if (sw[k] > 0) pts[k] = {sx[k] / sw[k], sy[k] / sw[k]};
  }
}

}  // namespace

TEST_CASE("relaxation gives the same dots bit for bit on 1, 2 or 3 threads, and as one plain pass", "[stipple][threads]") {
  struct Case {
    int w, h, dots;
    double a, b;
  };
  // Bands of rows (16 and 64) that do not divide the height; 24,000 dots (windows found on
  // threads from 20,000); radii to 40 cells (windows of 120 rows, over three bands of 64).
  for (const Case& c : {Case{157, 213, 2000, 1.2, 6}, Case{430, 389, 24000, 1.2, 6}, Case{331, 297, 300, 4, 40}}) {
    const int w = c.w, h = c.h;
    Rng rng(7);
    std::vector<uint8_t> plane(static_cast<size_t>(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)  // a ramp with noise, and a white corner no dot may enter
        plane[static_cast<size_t>(y) * w + x] =
            x > w - 27 && y < 20 ? 255 : static_cast<uint8_t>(std::min(254.0, 255.0 * x / w + rng.below(40)));
    const pds::RadiusTable radius = pds::RadiusTable::tone(c.a, c.b);
    std::vector<Vec2> start;
    for (int i = 0; i < c.dots; ++i) start.push_back({rng.uniform() * w, rng.uniform() * h});
    std::vector<Vec2> expect = start;
    relax_serial(expect, plane, radius, w, h, 4);
    for (int threads : {1, 2, 3}) {
      set_thread_count(threads);
      std::vector<Vec2> got = start;
      relax_points(got, plane, radius, w, h, 4);
      INFO(w << "x" << h << ", " << c.dots << " dots, " << threads << " threads");
      REQUIRE(got.size() == expect.size());
      CHECK(std::memcmp(got.data(), expect.data(), got.size() * sizeof(Vec2)) == 0);
      CHECK(got != start);  // the dots moved
    }
  }
  set_thread_count(0);
}
