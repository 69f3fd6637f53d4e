#pragma once
// The planner: from a Drawing (whatever method made it) to a Plan, the pen's
// strokes in plot order, layer by layer, with as little pen-up travel as the time
// budget allows.
#include <string>

#include "geometry/drawing.hpp"
#include "plan/plan.hpp"
#include "plan/strokes.hpp"

namespace stipplot {

struct PlanOptions {
  // The improvement's work budget: after 2-opt and Or-opt reach a local optimum,
  // perturbation trials, this many per point (dot, circle or polyline end) of the first
  // kTrialPointCeiling points, shared among layers by size; 0 = the local optimum only.
  // Work, not time, so the same drawing and options give the same plan on any machine
  // at any load.
  double optimize_effort = 0.3;
  static constexpr double kTrialPointCeiling = 300000;
  // Wall-clock cap on the improvement for the whole drawing, shared among layers by
  // their size; 0 = greedy construction only. Only when it trips (PlanInfo::budget_hit)
  // does the plan depend on the machine's speed.
  double optimize_seconds = 60.0;
  double join_tolerance_mm = 0.05;  // polyline ends closer than this are one vertex
  plan::FillMode fill = plan::FillMode::Spiral;
  double fill_pitch = 0.9;          // fill passes this fraction of the pen width apart
  double chord_tolerance_mm = 0.01; // circles drawn as polygons within this
  int neighbors = 10;               // 2-opt/Or-opt candidates per point
  Vec2 origin{0, 0};                // where the pen starts
  // Areas (filled shapes): hatched at this spacing (0: fill_pitch x the pen width) and
  // angle; --fill none leaves them to their outlines, which are the drawing's lines.
  double hatch_spacing_mm = 0;
  double hatch_angle_degrees = 45;
  // Path operations (plan/path_ops.hpp), off at their defaults.
  double simplify_mm = 0;           // polylines simplified within this
  double min_length_mm = 0;         // polyline strokes shorter than this are not drawn
  int passes = 1;                   // every stroke drawn this many times (multipass)
  bool reloop = false;              // closed strokes start where the travel is shortest
  void validate() const;            // UserError naming the option
};

// Layers with the same pen number (Pen::number; 0 is the layer's position, see
// resolve_pen_numbers) are planned as one, at the first one's place, so each pen is
// taken up once; the others keep their order (empty ones are kept, so pen numbers stay).
// Per pen: dots of at most the pen width become pen touches and larger ones filled
// circles; polylines are joined through shared ends into the fewest strokes their graph
// allows (a tree's segments: half its odd-degree vertices), then simplified and filtered
// by length; circles are outlined or filled, areas hatched; every stroke is given its
// passes; then all strokes are ordered as an open travelling-salesman path (each stroke
// in either direction) from where the previous pen ended, and relooped. A pen whose
// circles come in passes (Circle::pass) gets one such path a pass, lowest first.
// Time: O(P + n k log n) to build strokes, candidate lists and the greedy edge tour
// (P points, n strokes, k = neighbors), then the local search and the trials, O(n) work
// per unit of effort in practice (see plan/tour.hpp).
Plan plan_drawing(const Drawing& d, const PlanOptions& opt);

// How planning went, for --json reports and benchmarks.
struct PlanInfo {
  double seconds = 0;        // wall time of plan_drawing
  bool budget_hit = false;   // the wall-clock cap stopped some layer's improvement
  long improving_moves = 0;  // 2-opt + Or-opt moves applied
};
Plan plan_drawing(const Drawing& d, const PlanOptions& opt, PlanInfo* info);
// The same plan from a drawing given up: each layer's primitives are freed once they are
// strokes, before the tour (a 1M-dot drawing: 24 MB less at the planner's peak).
Plan plan_drawing(Drawing&& d, const PlanOptions& opt, PlanInfo* info = nullptr);

// Pen-up length of a plan: from `start` to each stroke's first point from the previous
// stroke's last, across layers (what the planner keeps small). O(strokes).
double pen_up_travel(const Plan& plan, Vec2 start = {0, 0});

}  // namespace stipplot
