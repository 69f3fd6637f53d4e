#include "budget/mark_costs.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

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

double MarkCosts::path_link_s(double link_mm, double turn_degrees) const {
  if (!(link_mm > 0)) return 0;
  const std::pair<long, long> key{std::lround(link_mm * 100), std::lround(turn_degrees)};
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (auto it = link_.find(key); it != link_.end()) return it->second;
  }
  // 64 links; the first and last 8 (the path's start and stop) are left out.
  constexpr int kLinks = 64, kEdge = 8;
  const double len = std::max(key.first, 1L) / 100.0, turn = key.second * M_PI / 180;
  std::vector<Vec2> pts{{0, 0}};
  double heading = 0;
  for (int i = 0; i < kLinks; ++i) {
    heading += (i % 2 ? turn : -turn);
    pts.push_back({pts.back().x + len * std::cos(heading), pts.back().y + len * std::sin(heading)});
  }
  const std::vector<Vec2> ends(pts.begin(), pts.begin() + kEdge + 1);
  const std::vector<Vec2> tail(pts.end() - kEdge - 1, pts.end());
  const double all = motion::polyline_seconds(pts, m_.speed_down_mm_s, m_);
  const double edges = motion::polyline_seconds(ends, m_.speed_down_mm_s, m_) + motion::polyline_seconds(tail, m_.speed_down_mm_s, m_);
  const double t = std::max(all - edges, 0.0) / (kLinks - 2 * kEdge) * (link_mm / len);
  std::lock_guard<std::mutex> lock(mu_);
  link_[key] = t;
  return t;
}

double quick_estimate_seconds(const Drawing& d, const MotionParams& motion, PlanOptions po) {
  po.optimize_seconds = 0;
  return motion::simulate_motion(plan_drawing(d, po), motion, po.origin).total_seconds;
}

}  // namespace stipplot::budget
