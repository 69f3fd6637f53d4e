#include "serve/plot_trace.hpp"

#include "drivers/device/machine.hpp"

namespace stipplot::serve {

TracePlacement placement_from_summary(const nlohmann::json& s, const DeviceProfile& device) {
  TracePlacement p;
  p.page_w_mm = device.machine.sheet_width_mm;
  p.page_h_mm = device.machine.sheet_height_mm;
  if (s.is_object() && s.contains("page_mm") && s["page_mm"].size() == 2) {
    p.page_w_mm = s["page_mm"][0].get<double>();
    p.page_h_mm = s["page_mm"][1].get<double>();
  }
  if (s.is_object() && s.contains("layout") && s["layout"].contains("transform")) {
    const auto& t = s["layout"]["transform"];
    const Affine a{t[0].get<double>(), t[1].get<double>(), t[2].get<double>(),
                   t[3].get<double>(), t[4].get<double>(), t[5].get<double>()};
    if (a.det() != 0) p.page_to_sheet = a;
  }
  return p;
}

nlohmann::json job_trace(const io::Job& job, const DeviceProfile& device, bool hpgl, const TracePlacement& where) {
  const Page sheet{device.machine.sheet_width_mm, device.machine.sheet_height_mm};
  const MachineTransform machine(device, sheet);
  const Affine sheet_to_page = where.page_to_sheet.inverse();
  // G-code coordinates are machine millimetres; HPGL's are plotter units (steps).
  const double mm_per_unit = hpgl ? machine.step_mm() : 1.0;
  auto on_page = [&](double x, double y) { return sheet_to_page.apply(machine.to_page_mm({x * mm_per_unit, y * mm_per_unit})); };
  nlohmann::json segs = nlohmann::json::array();
  double x = 0, y = 0;
  bool down = false;
  auto add = [&](size_t line, double x0, double y0, double x1, double y1) {
    const Vec2 p = on_page(x0, y0), q = on_page(x1, y1);
    segs.push_back({line, p.x, p.y, q.x, q.y});
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
  return {{"lines", job.lines.size()}, {"page_mm", {where.page_w_mm, where.page_h_mm}}, {"segments", segs}};
}

}  // namespace stipplot::serve
