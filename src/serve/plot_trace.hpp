#pragma once
// What each line of a job draws, for the page to draw the plot's progress over the
// method's preview: every pen-down move and every touch (pen down and up in one place),
// tagged with the job line whose acknowledgement means it is on the paper, and placed
// on the method's own page, where the preview shows the drawing.
#include <nlohmann/json.hpp>
#include <string>

#include "drivers/device/profile.hpp"
#include "drivers/job/job.hpp"
#include "geometry/affine.hpp"

namespace stipplot::serve {

// Where the job's drawing came from: the method's page and how the layout put it on the
// device's sheet (the method's --json "page_mm" and "layout"."transform"). Without it the
// job is taken to lie on the sheet as it is.
struct TracePlacement {
  double page_w_mm = 0, page_h_mm = 0;
  Affine page_to_sheet;
};
TracePlacement placement_from_summary(const nlohmann::json& method_summary, const DeviceProfile& device);

// {"lines": N, "page_mm": [w, h], "segments": [[line, x0, y0, x1, y1], ...]} with points in
// the method page's millimetres (origin top-left, y down). O(job lines).
nlohmann::json job_trace(const io::Job& job, const DeviceProfile& device, bool hpgl, const TracePlacement& where);

}  // namespace stipplot::serve
