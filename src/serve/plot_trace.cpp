#include "serve/plot_trace.hpp"

#include <algorithm>
#include <limits>

namespace stipplot::serve {

nlohmann::json job_trace(const io::Job& job, bool y_up, double units_per_mm) {
  nlohmann::json segs = nlohmann::json::array();
  double x = 0, y = 0;
  bool down = false;
  double lo_x = std::numeric_limits<double>::max(), lo_y = lo_x, hi_x = -lo_x, hi_y = -lo_x;
  auto add = [&](size_t line, double x0, double y0, double x1, double y1) {
    segs.push_back({line, x0, y0, x1, y1});
    lo_x = std::min({lo_x, x0, x1});
    hi_x = std::max({hi_x, x0, x1});
    lo_y = std::min({lo_y, y0, y1});
    hi_y = std::max({hi_y, y0, y1});
  };
  for (size_t i = 0; i < job.lines.size(); ++i) {
    const io::JobLine& l = job.lines[i];
    if (l.pen_down && l.motion) add(i, x, y, l.x, l.y);
    else if (l.pen_down && !down) add(i, x, y, x, y);  // the pen goes down here: a touch, or a stroke's start
    if (l.motion) {
      x = l.x;
      y = l.y;
    }
    down = l.pen_down;
  }
  if (segs.empty()) lo_x = lo_y = hi_x = hi_y = 0;
  return {{"lines", job.lines.size()},
          {"y_up", y_up},
          {"units_per_mm", units_per_mm},
          {"bounds", {lo_x, lo_y, hi_x, hi_y}},
          {"segments", segs}};
}

}  // namespace stipplot::serve
