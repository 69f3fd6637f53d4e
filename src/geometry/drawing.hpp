#pragma once
// The Drawing model: the only thing later stages (planner, writers, preview,
// drivers) see of a method's output. All coordinates are millimetres on the page,
// origin top-left, y down (as SVG).
#include <cstddef>
#include <string>
#include <vector>

#include "geometry/color.hpp"

namespace stipplot {

struct Vec2 {
  double x = 0, y = 0;
  friend bool operator==(const Vec2&, const Vec2&) = default;
};

struct Pen {
  std::string name = "black";
  Color color = colors::black;
  double width_mm = 0.3;
};

struct Dot {
  Vec2 c;
  double diameter = 0.3;  // mm; at most the pen width means one pen touch
};

struct Polyline {
  std::vector<Vec2> pts;  // a closed shape repeats its first point at the end
};

struct Circle {
  Vec2 c;
  double r = 0;  // mm
  bool filled = false;
  Color fill = colors::black;  // exact fill colour for SVG/preview; plotters use the pen
};

struct Layer {
  Pen pen;
  std::vector<Dot> dots;
  std::vector<Polyline> lines;
  std::vector<Circle> circles;
  size_t primitive_count() const { return dots.size() + lines.size() + circles.size(); }
};

struct Page {
  double width_mm = 210, height_mm = 297;
  Color paper = colors::white;
};

struct Drawing {
  Page page;
  std::vector<Layer> layers;
  size_t primitive_count() const;
  // Bounding box of every primitive (including dot/circle extents); false if empty.
  bool bounds(Vec2& lo, Vec2& hi) const;
};

}  // namespace stipplot
