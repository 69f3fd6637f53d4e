#pragma once
// Test-only helpers: Plans built by hand, without the planner. `plan_in_given_order`
// takes a Drawing's primitives in the order they are stored (dots as single-point
// strokes, polylines as they are); it does no ordering at all and is not a planner.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "plan/plan.hpp"
#include "util/rng.hpp"

namespace stipplot::fixtures {

inline Plan plan_in_given_order(const Drawing& d) {
  Plan p;
  p.page = d.page;
  for (const auto& l : d.layers) {
    PlannedLayer pl;
    pl.pen = l.pen;
    for (const auto& dot : l.dots) pl.strokes.push_back({{dot.c}});
    for (const auto& line : l.lines) pl.strokes.push_back({line.pts});
    p.layers.push_back(std::move(pl));
  }
  return p;
}

// A random plan on a page (A4 portrait by default) inside a margin: per layer some dots and
// some polylines of 2..9 points.
inline Plan random_plan(uint64_t seed, int layers, int dots, int lines, double w = 210, double h = 297,
                        double margin = 10) {
  const double m = margin;
  Rng rng(seed);
  Drawing d;
  d.page.width_mm = w;
  d.page.height_mm = h;
  const char* names[] = {"black", "red", "blue", "green", "cyan", "magenta", "yellow", "orange"};
  for (int li = 0; li < layers; ++li) {
    Layer l;
    l.pen.name = names[li % 8];
    for (int i = 0; i < dots; ++i) l.dots.push_back({{m + rng.uniform() * (w - 2 * m), m + rng.uniform() * (h - 2 * m)}, 0.3});
    for (int i = 0; i < lines; ++i) {
      Polyline pl;
      int n = 2 + static_cast<int>(rng.uniform() * 8);
      Vec2 p{m + rng.uniform() * (w - 2 * m), m + rng.uniform() * (h - 2 * m)};
      for (int k = 0; k < n; ++k) {
        pl.pts.push_back(p);
        p.x = std::clamp(p.x + (rng.uniform() - 0.5) * 20, m, w - m);
        p.y = std::clamp(p.y + (rng.uniform() - 0.5) * 20, m, h - m);
      }
      l.lines.push_back(pl);
    }
    d.layers.push_back(l);
  }
  return plan_in_given_order(d);
}

}  // namespace stipplot::fixtures
