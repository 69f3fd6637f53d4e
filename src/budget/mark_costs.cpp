#include "budget/mark_costs.hpp"

#include <cmath>

#include "drivers/motion/time_model.hpp"
#include "plan/strokes.hpp"

namespace stipplot::budget {

MarkCosts::MarkCosts(const MotionParams& motion, const PlanOptions& plan) : m_(motion), po_(plan) {
  validate(m_);
  po_.validate();
}

double MarkCosts::travel_s(double mm) const {
  if (!(mm > 0)) return 0;
  return motion::polyline_seconds({{0, 0}, {mm, 0}}, m_.speed_up_mm_s, m_);
}

double MarkCosts::line_s(double mm) const {
  if (!(mm > 0)) return 0;
  return motion::polyline_seconds({{0, 0}, {mm, 0}}, m_.speed_down_mm_s, m_);
}

double MarkCosts::disc_s(double diameter_mm, double pen_mm) const {
  if (!(diameter_mm > pen_mm)) return 0;
  const std::pair<long, long> key{std::lround(diameter_mm * 100), std::lround(pen_mm * 100)};
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (auto it = disc_.find(key); it != disc_.end()) return it->second;
  }
  plan::FillOptions fill;
  fill.mode = po_.fill;
  fill.pen_width = pen_mm;
  fill.pitch_fraction = po_.fill_pitch;
  fill.chord_tolerance = po_.chord_tolerance_mm;
  const Stroke s = plan::circle_stroke(Circle{{0, 0}, key.first / 200.0, true, colors::black}, fill);
  const double t = motion::polyline_seconds(s.pts, m_.speed_down_mm_s, m_);
  std::lock_guard<std::mutex> lock(mu_);
  disc_[key] = t;
  return t;
}

double MarkCosts::zigzag_s(double mm, int passes, double spacing_mm) const {
  std::vector<Vec2> pts;
  for (int k = 0; k < passes; ++k) {
    const double y = k * spacing_mm;
    const bool forward = k % 2 == 0;
    pts.push_back({forward ? 0 : mm, y});
    pts.push_back({forward ? mm : 0, y});
  }
  return motion::polyline_seconds(pts, m_.speed_down_mm_s, m_);
}

double quick_estimate_seconds(const Drawing& d, const MotionParams& motion, PlanOptions po) {
  po.optimize_seconds = 0;
  return motion::simulate_motion(plan_drawing(d, po), motion, po.origin).total_seconds;
}

}  // namespace stipplot::budget
