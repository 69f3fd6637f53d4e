#pragma once
// From page millimetres (origin top-left, y down) to a device's own coordinates, in
// whole device steps (resolution_mm for grbl, plotter units for HPGL), and the check
// that a plan fits the device before anything is written or sent.
#include <cstdint>

#include "drivers/device/profile.hpp"
#include "drivers/job/job.hpp"
#include "geometry/drawing.hpp"
#include "plan/plan.hpp"

namespace stipplot {

struct Steps {
  int64_t x = 0, y = 0;
  friend bool operator==(const Steps&, const Steps&) = default;
};

class MachineTransform {
 public:
  MachineTransform(const DeviceProfile& profile, const Page& page);
  // Machine position in mm (not rounded).
  Vec2 to_machine_mm(Vec2 page_mm) const;
  // Its inverse: where a machine position (mm) lies on the page.
  Vec2 to_page_mm(Vec2 machine_mm) const;
  // Rounded to the device's resolution.
  Steps to_steps(Vec2 page_mm) const;
  bool inside(Steps s) const {
    return s.x >= lo_.x && s.x <= hi_.x && s.y >= lo_.y && s.y <= hi_.y;
  }
  // Where machine zero (the pen's start) lies on the page, in page mm.
  Vec2 page_position_of_machine_zero() const;
  // The part of the page the travel covers, in page mm (every point in it passes
  // check_plan_fits' travel test).
  Rect reach_on_page() const;
  double step_mm() const { return step_; }
  Steps lo() const { return lo_; }
  Steps hi() const { return hi_; }

 private:
  const MachineGeometry& m_;
  double page_h_;
  double step_;
  Steps lo_, hi_;
};

// Throws UserError naming the first plan point that is off the page or (page mm and
// machine mm) outside the profile's travel, before anything is written or sent.
// O(total points).
void check_plan_fits(const Plan& plan, const DeviceProfile& profile);
// A job file's every position (G-code mm, HPGL plotter units) inside the profile's
// travel, to within half a step; throws UserError naming the first line outside.
// O(lines).
void check_job_fits(const io::Job& job, const DeviceProfile& profile, const std::string& path);
}  // namespace stipplot
