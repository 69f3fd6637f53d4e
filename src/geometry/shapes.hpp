#pragma once
// Polygons standing for round shapes, shared by the stages that must turn a circle into
// points (the planner's outlines and fills, the layout's clipping).
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot {

// Largest angle step whose chord stays within `tol` of an arc of radius r (at most 45°).
double chord_angle_step(double r, double tol);

// A closed polygon within `chord_tolerance` of the circle, starting at `start_angle`
// (radians, clockwise on a y-down page), first point repeated at the end; at least 8
// sides. O(r / sqrt(tolerance)) points.
std::vector<Vec2> circle_points(Vec2 c, double r, double chord_tolerance, double start_angle = 0);

}  // namespace stipplot
