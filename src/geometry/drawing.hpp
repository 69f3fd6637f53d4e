#pragma once
// The Drawing model: the only thing later stages (planner, writers, preview,
// drivers) see of a method's output. All coordinates are millimetres on the page,
// origin top-left, y down (as SVG).
#include <cstddef>
#include <string>
#include <vector>

#include "geometry/color.hpp"

namespace stipplot {

// No coordinate of a drawing lies farther than this from the page's origin (1 km): readers
// refuse more, so the planner's grids and the writers' integer units cannot overflow.
inline constexpr double kMaxCoordinateMm = 1e6;

struct Vec2 {
  double x = 0, y = 0;
  friend bool operator==(const Vec2&, const Vec2&) = default;
};

struct Pen {
  std::string name = "black";
  Color color = colors::black;
  double width_mm = 0.3;
  // The device's pen for this layer (1, 2, ...); 0: the layer's position (layer i, pen i).
  // Layers given the same number are drawn with one pen, one after the other.
  int number = 0;
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
  // Within its layer's pen, circles of a lower pass are drawn before those of a higher one
  // (a pointillist's ebauche before the dots over it: wet ink is not dragged through);
  // the planner orders each pass on its own. Lines, dots and areas are in pass 0.
  int pass = 0;
};

// Which points a set of rings fills (SVG's fill-rule): nonzero winding, or an odd number
// of crossings (so a ring inside another is a hole either way when they run opposite).
enum class FillRule { nonzero, evenodd };

// A filled region: closed rings (each repeats its first point at the end); the rule says
// which points are inside, so holes are rings it leaves empty. A plotter draws it as a
// hatch at the pen width; SVG and the preview fill it.
struct Area {
  std::vector<Polyline> rings;
  FillRule rule = FillRule::nonzero;
  Color fill = colors::black;  // exact fill colour for SVG/preview; plotters use the pen
};

struct Layer {
  Pen pen;
  std::vector<Dot> dots;
  std::vector<Polyline> lines;
  std::vector<Circle> circles;
  std::vector<Area> areas;
  size_t primitive_count() const { return dots.size() + lines.size() + circles.size() + areas.size(); }
};

struct Page {
  double width_mm = 210, height_mm = 297;
  Color paper = colors::white;
};

// An axis-aligned rectangle in page millimetres.
struct Rect {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  double width() const { return x1 - x0; }
  double height() const { return y1 - y0; }
  bool empty() const { return !(x1 > x0 && y1 > y0); }
  bool contains(Vec2 p) const { return p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1; }
  Rect intersect(const Rect& o) const;
};

struct Drawing {
  Page page;
  std::vector<Layer> layers;
  size_t primitive_count() const;
  // Bounding box of every primitive (including dot/circle extents); false if empty.
  bool bounds(Vec2& lo, Vec2& hi) const;
};

// Gives every layer without a pen number (0) the lowest number no other layer has, in
// layer order, so numbered layers keep theirs and unnumbered ones never share a pen by
// accident (layers 1 and "2 red" and an unnumbered one: 1, 2, 3). O(layers log layers).
void resolve_pen_numbers(Drawing& d);

// One layer a pen: layers with the same pen (name, colour, width and number) become the
// first one, the others' primitives appended in layer order (so each keeps its circles'
// passes), then the layers are ordered light to dark by the relative luminance of the pen
// colour (stable), so a dark ink is never dragged through a light one and each pen is
// taken up once. O(primitives + layers^2).
void merge_layers_by_pen(Drawing& d);

// The relative luminance of an sRGB colour (0 black .. 1 white), as WCAG defines it.
double relative_luminance(Color c);

}  // namespace stipplot
