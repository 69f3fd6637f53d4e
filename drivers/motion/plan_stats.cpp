#include "drivers/motion/plan_stats.hpp"

#include <cmath>

namespace stipplot {

namespace {
double dist(Vec2 a, Vec2 b) { return std::hypot(a.x - b.x, a.y - b.y); }
}  // namespace

PlanStats plan_stats(const Plan& plan, const MotionParams& m, Vec2 origin, bool return_home) {
  PlanStats st = plan_lengths(plan, origin, return_home);
  const motion::MotionTimeline tl = motion::simulate_motion(plan, m, origin, return_home);
  for (size_t li = 0; li < st.layers.size(); ++li) st.layers[li].seconds = tl.layer_seconds[li];
  st.total.seconds = tl.total_seconds;
  return st;
}

PlanStats plan_lengths(const Plan& plan, Vec2 origin, bool return_home) {
  PlanStats st;
  Vec2 pos = origin;
  st.total.pen = "total";
  for (size_t li = 0; li < plan.layers.size(); ++li) {
    const PlannedLayer& layer = plan.layers[li];
    LayerStats ls;
    ls.pen = layer.pen.name;
    for (const Stroke& s : layer.strokes) {
      if (s.pts.empty()) continue;
      ++ls.strokes;
      ++ls.pen_lifts;
      if (s.pts.size() == 1) ++ls.touches;
      ls.pen_up_mm += dist(pos, s.pts.front());
      for (size_t k = 1; k < s.pts.size(); ++k) ls.pen_down_mm += dist(s.pts[k - 1], s.pts[k]);
      pos = s.pts.back();
    }
    st.total.strokes += ls.strokes;
    st.total.touches += ls.touches;
    st.total.pen_lifts += ls.pen_lifts;
    st.total.pen_down_mm += ls.pen_down_mm;
    st.total.pen_up_mm += ls.pen_up_mm;
    st.layers.push_back(std::move(ls));
  }
  if (return_home) st.home_mm = dist(pos, origin);
  st.total.pen_up_mm += st.home_mm;
  return st;
}

nlohmann::json to_json(const LayerStats& s) {
  return {{"pen", s.pen},           {"strokes", s.strokes},         {"touches", s.touches},
          {"pen_lifts", s.pen_lifts}, {"pen_down_mm", s.pen_down_mm}, {"pen_up_mm", s.pen_up_mm},
          {"seconds", s.seconds}};
}

nlohmann::json to_json(const PlanStats& s) {
  nlohmann::json layers = nlohmann::json::array();
  for (const auto& l : s.layers) layers.push_back(to_json(l));
  return {{"layers", layers}, {"total", to_json(s.total)}, {"home_mm", s.home_mm}};
}

}  // namespace stipplot
