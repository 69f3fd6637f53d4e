#pragma once
// What marks cost on a machine, from the motion model (drivers/motion) and the
// planner's own fills: the prices a method's density prediction adds up. Every time is
// from rest to rest, as the planner leaves each stroke (pen events flush grbl's planner).
#include <map>
#include <mutex>

#include "drivers/motion/motion_params.hpp"
#include "geometry/drawing.hpp"
#include "plan/planner.hpp"

namespace stipplot::budget {

class MarkCosts {
 public:
  MarkCosts(const MotionParams& motion, const PlanOptions& plan);
  const MotionParams& motion() const { return m_; }
  const PlanOptions& plan_options() const { return po_; }
  // One pen drop and lift.
  double pen_cycle_s() const { return m_.pen_drop_s + m_.pen_lift_s; }
  // A pen-up move of `mm`, a straight pen-down line of `mm`.
  double travel_s(double mm) const;
  double line_s(double mm) const;
  // Drawing a filled dot of `diameter_mm` with a `pen_mm` pen as the planner fills it
  // (0 for a touch, no wider than the pen), pen events excluded. Memoised per 0.01 mm:
  // O(fill points x look-ahead) once a size, O(log sizes) after.
  double disc_s(double diameter_mm, double pen_mm) const;
  // A zigzag of `passes` parallel lines of `mm` each, `spacing_mm` apart, drawn in one
  // pen-down (the sketch's strokes).
  double zigzag_s(double mm, int passes, double spacing_mm) const;
  // A link of `link_mm` inside a long pen-down path of equal links turning alternately by
  // +-`turn_degrees` (a tour through points: grbl slows at every corner by its junction
  // deviation). Memoised per 0.01 mm and degree: O(64 links) once, O(log sizes) after.
  double path_link_s(double link_mm, double turn_degrees) const;

 private:
  MotionParams m_;
  PlanOptions po_;
  mutable std::mutex mu_;
  mutable std::map<std::pair<long, long>, double> disc_, link_;
};

// A quick upper bound of a drawing's plot time: the planner's strokes in greedy
// nearest-neighbour order (no 2-opt: that only shortens travel) from `po.origin`, timed
// by the motion model. O(P + n log n) for P points and n strokes.
double quick_estimate_seconds(const Drawing& d, const MotionParams& motion, PlanOptions po);

}  // namespace stipplot::budget
