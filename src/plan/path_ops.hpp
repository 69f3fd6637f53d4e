#pragma once
// Operations on a layer's strokes that vpype users know: linesimplify, filter
// --min-length, multipass and reloop. The planner applies them (planner.hpp says when).
#include <vector>

#include "plan/plan.hpp"

namespace stipplot::plan {

// Douglas-Peucker: drops points while the stroke stays within `tolerance` mm of the
// original; the ends are kept. O(n log n) typical, O(n^2) for adversarial zigzags.
void simplify_stroke(Stroke& s, double tolerance);

// Pen-down length of a stroke. O(points).
double stroke_length(const Stroke& s);

// True if the stroke ends where it starts and encloses something (at least 3 points).
bool is_closed(const Stroke& s);

// Draws the stroke `passes` times without lifting: a closed stroke goes round again, an
// open one back and forth (so it ends at its start after an even number). O(points x passes).
void multipass_stroke(Stroke& s, int passes);

// Reloop: every closed stroke in `order` is rotated to start at the vertex where the pen
// coming from the previous stroke's end (`start` for the first) and leaving for the next
// stroke's start travels least. Strokes keep their order. O(points).
void reloop_strokes(std::vector<Stroke>& strokes, Vec2 start);

}  // namespace stipplot::plan
