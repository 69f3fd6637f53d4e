#include "drivers/device/machine.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "util/error.hpp"

namespace stipplot {

MachineTransform::MachineTransform(const DeviceProfile& profile, const Page& page)
    : m_(profile.machine), page_h_(page.height_mm), step_(m_.resolution_mm) {
  // Travel in whole steps; a hair of slack so 276 mm at 0.025 mm is 11040 steps, not 11039.
  const int64_t nx = static_cast<int64_t>(std::floor(m_.travel_x_mm / step_ + 1e-6));
  const int64_t ny = static_cast<int64_t>(std::floor(m_.travel_y_mm / step_ + 1e-6));
  lo_ = {m_.x_sign > 0 ? 0 : -nx, m_.y_sign > 0 ? 0 : -ny};
  hi_ = {m_.x_sign > 0 ? nx : 0, m_.y_sign > 0 ? ny : 0};
}

Vec2 MachineTransform::to_machine_mm(Vec2 p) const {
  const double dx = p.x;
  const double dy = m_.origin == Origin::top_left ? p.y : page_h_ - p.y;
  return {m_.x_sign * (dx - m_.origin_offset_x_mm), m_.y_sign * (dy - m_.origin_offset_y_mm)};
}

Vec2 MachineTransform::to_page_mm(Vec2 mm) const {
  const double dy = mm.y / m_.y_sign + m_.origin_offset_y_mm;
  return {mm.x / m_.x_sign + m_.origin_offset_x_mm, m_.origin == Origin::top_left ? dy : page_h_ - dy};
}

Vec2 MachineTransform::page_position_of_machine_zero() const {
  return {m_.origin_offset_x_mm,
          m_.origin == Origin::top_left ? m_.origin_offset_y_mm : page_h_ - m_.origin_offset_y_mm};
}

Rect MachineTransform::reach_on_page() const {
  // The travel's corners back on the page.
  const Vec2 p = to_page_mm({lo_.x * step_, lo_.y * step_}), q = to_page_mm({hi_.x * step_, hi_.y * step_});
  return {std::min(p.x, q.x), std::min(p.y, q.y), std::max(p.x, q.x), std::max(p.y, q.y)};
}

Steps MachineTransform::to_steps(Vec2 page_mm) const {
  Vec2 m = to_machine_mm(page_mm);
  return {std::llround(m.x / step_), std::llround(m.y / step_)};
}

void check_plan_fits(const Plan& plan, const DeviceProfile& profile) {
  MachineTransform t(profile, plan.page);
  for (size_t li = 0; li < plan.layers.size(); ++li) {
    for (const auto& s : plan.layers[li].strokes) {
      for (const auto& p : s.pts) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y))
          throw UserError("plan layer " + std::to_string(li + 1) + " has a non-finite coordinate");
        const double slack = t.step_mm() / 2;
        if (p.x < -slack || p.y < -slack || p.x > plan.page.width_mm + slack || p.y > plan.page.height_mm + slack) {
          std::ostringstream msg;
          msg.precision(2);
          msg << std::fixed << "point (" << p.x << ", " << p.y << ") mm (layer " << li + 1 << ") is off the "
              << plan.page.width_mm << " x " << plan.page.height_mm << " mm page";
          throw UserError(msg.str());
        }
        if (t.inside(t.to_steps(p))) continue;
        Vec2 m = t.to_machine_mm(p);
        std::ostringstream msg;
        msg.precision(2);
        msg << std::fixed << "point (" << p.x << ", " << p.y << ") mm on the page (layer " << li + 1
            << ") is at machine (" << m.x << ", " << m.y << ") mm, outside the travel of profile "
            << profile.name << " (" << t.lo().x * t.step_mm() << ".." << t.hi().x * t.step_mm() << " x "
            << t.lo().y * t.step_mm() << ".." << t.hi().y * t.step_mm()
            << " mm); --fit lays the drawing inside what the device reaches (or use --scale, a larger --margin "
               "with --fit or --align, or another profile)";
        throw UserError(msg.str());
      }
    }
  }
}

void check_job_fits(const io::Job& job, const DeviceProfile& profile, const std::string& path) {
  const MachineGeometry& m = profile.machine;
  const bool hpgl = job.dialect == io::Dialect::Hpgl;
  const double per_mm = hpgl ? m.units_per_mm : 1.0;  // the job's units per mm
  const double slack = 0.5 * (hpgl ? 1.0 / m.units_per_mm : m.resolution_mm);
  const double x_lo = m.x_sign > 0 ? 0 : -m.travel_x_mm, x_hi = m.x_sign > 0 ? m.travel_x_mm : 0;
  const double y_lo = m.y_sign > 0 ? 0 : -m.travel_y_mm, y_hi = m.y_sign > 0 ? m.travel_y_mm : 0;
  for (size_t i = 0; i < job.lines.size(); ++i) {
    const io::JobLine& l = job.lines[i];
    const double x = l.x / per_mm, y = l.y / per_mm;
    if (x >= x_lo - slack && x <= x_hi + slack && y >= y_lo - slack && y <= y_hi + slack) continue;
    std::ostringstream msg;
    msg << path << " line " << i + 1 << " `" << l.text.substr(0, 60) << "` goes to (" << x << ", " << y
        << ") mm, outside the travel of profile " << profile.name << " (X " << x_lo << ".." << x_hi << ", Y " << y_lo
        << ".." << y_hi << " mm); nothing was sent";
    throw UserError(msg.str());
  }
}

}  // namespace stipplot
