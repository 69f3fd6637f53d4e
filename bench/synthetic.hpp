#pragma once
// Photo-like test images made in the benchmark itself: smooth value noise (several
// octaves) plus hard-edged shapes and thin lines, deterministic.
#include <cmath>
#include <cstdint>
#include <vector>

#include "geometry/drawing.hpp"
#include "image/image.hpp"
#include "util/rng.hpp"

namespace stipplot::bench {

inline std::vector<uint8_t> photo_like_grey(int w, int h, uint64_t seed = 7) {
  Rng rng(seed);
  std::vector<float> acc(static_cast<size_t>(w) * h, 0.f);
  float amp = 0.5f;
  for (int cell = 256; cell >= 16; cell /= 2, amp *= 0.55f) {
    int gw = w / cell + 2, gh = h / cell + 2;
    std::vector<float> g(static_cast<size_t>(gw) * gh);
    for (auto& v : g) v = static_cast<float>(rng.uniform());
    for (int y = 0; y < h; ++y) {
      float fy = static_cast<float>(y) / cell;
      int y0 = static_cast<int>(fy);
      float ty = fy - y0;
      ty = ty * ty * (3 - 2 * ty);
      for (int x = 0; x < w; ++x) {
        float fx = static_cast<float>(x) / cell;
        int x0 = static_cast<int>(fx);
        float tx = fx - x0;
        tx = tx * tx * (3 - 2 * tx);
        auto at = [&](int i, int j) { return g[static_cast<size_t>(j) * gw + i]; };
        float v = (at(x0, y0) * (1 - tx) + at(x0 + 1, y0) * tx) * (1 - ty) +
                  (at(x0, y0 + 1) * (1 - tx) + at(x0 + 1, y0 + 1) * tx) * ty;
        acc[static_cast<size_t>(y) * w + x] += amp * v;
      }
    }
  }
  std::vector<uint8_t> out(acc.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float v = acc[static_cast<size_t>(y) * w + x] * 1.6f - 0.1f;
      // hard edges: a dark disc and a bright bar; thin dark lines every 97 px
      float dx = x - w * 0.3f, dy = y - h * 0.5f;
      if (dx * dx + dy * dy < (h * 0.2f) * (h * 0.2f)) v *= 0.35f;
      if (x > w * 0.6f && x < w * 0.75f) v = 0.6f + 0.4f * v;
      if ((x + 2 * y) % 97 == 0) v *= 0.2f;
      out[static_cast<size_t>(y) * w + x] = static_cast<uint8_t>(std::lround(255 * std::fmin(1.f, std::fmax(0.f, v))));
    }
  return out;
}

inline Image photo_like(int w, int h, uint64_t seed = 7) { return Image::from_grey(w, h, photo_like_grey(w, h, seed)); }

// n points uniform in a side x side mm square: the planner's benchmark instances.
inline std::vector<Vec2> uniform_dots(size_t n, double side, uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec2> p(n);
  for (auto& v : p) v = {rng.uniform() * side, rng.uniform() * side};
  return p;
}

}  // namespace stipplot::bench
