#pragma once
// Turning a layer's primitives into pen strokes: polylines joined through shared
// ends (a tree's segments become as few strokes as its graph allows), and circles
// and big dots filled at the pen width.
#include <vector>

#include "geometry/drawing.hpp"
#include "plan/plan.hpp"

namespace stipplot::plan {

// Treats every polyline as an edge between its end points (ends within `tolerance`
// mm are one vertex, found by hashing on a grid) and covers each connected component
// with the fewest strokes possible: max(1, odd-degree vertices / 2). Odd vertices are
// paired (nearest first) by virtual pen-up edges, Hierholzer's algorithm walks an
// Euler circuit depth-first, and the circuit is cut at the virtual edges. Chains of
// polylines meeting end to end thus join into one stroke. Polylines of one point
// become pen touches. O(P + V log V) for P points and V vertices.
std::vector<Stroke> join_polylines(const std::vector<Polyline>& lines, double tolerance);

enum class FillMode { Spiral, Hatch, None };
FillMode parse_fill_mode(const std::string& name);  // throws UserError naming --fill
const char* to_string(FillMode m);

struct FillOptions {
  FillMode mode = FillMode::Spiral;
  double pen_width = 0.3;
  double pitch_fraction = 0.9;     // fill passes this fraction of the pen width apart (overlap)
  double chord_tolerance = 0.01;   // mm between a circle and its polygon
};

// A closed polygon approximating a circle within the chord tolerance, starting at
// angle `start_angle`, first point repeated at the end. O(r / sqrt(tolerance)) points.
Stroke circle_outline(Vec2 c, double r, double chord_tolerance, double start_angle = 0);

// One stroke for a circle: a pen touch if its diameter is at most the pen width; an
// outline at r if unfilled; if filled, an Archimedean spiral (or a zigzag hatch) from
// the centre out to r - pen/2 with passes at most pitch_fraction * pen apart, closed by
// an outline at r - pen/2, so every point of the disc is inked. O(r^2 / pen^2) points.
Stroke circle_stroke(const Circle& c, const FillOptions& opt);

}  // namespace stipplot::plan
