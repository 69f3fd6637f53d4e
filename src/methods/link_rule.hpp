#pragma once
// When a pen-down link between two marks should be a pen lift instead: the rule shared by
// connected stippling (stipple/connect.hpp) and linked sketch strokes (sketch/link.hpp).
#include <algorithm>
#include <cmath>

#include "geometry/drawing.hpp"

namespace stipplot {

// True when the link a-b is longer than `lift_length` x `spacing` (the larger of its ends'
// local spacings, mm), or when `tone` (the ink the ground wants, any scale), sampled every
// half `cell_mm` along it, averages below `lift_tone` x its two ends' mean. O(len / cell).
template <class Tone>
bool link_lifted(Vec2 a, Vec2 b, double spacing, double cell_mm, double lift_length, double lift_tone, const Tone& tone) {
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  if (len > lift_length * spacing) return true;
  const double ends = 0.5 * (tone(a) + tone(b));
  const int n = std::max(2, static_cast<int>(std::ceil(2 * len / cell_mm)) + 1);
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double f = static_cast<double>(i) / (n - 1);
    sum += tone(Vec2{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y)});
  }
  return sum / n < lift_tone * ends;
}

}  // namespace stipplot
