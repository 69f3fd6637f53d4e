#pragma once
// What each line of a job draws, for the page to draw the plot's progress: every
// pen-down move and every touch (pen down and up in one place), tagged with the job line
// whose acknowledgement means it is on the paper.
#include <nlohmann/json.hpp>
#include <string>

#include "drivers/job/job.hpp"

namespace stipplot::serve {

// {"lines": N, "y_up": bool, "units_per_mm": u, "bounds": [x0,y0,x1,y1],
//  "segments": [[line, x0, y0, x1, y1], ...]} in the job's own units. O(job lines).
nlohmann::json job_trace(const io::Job& job, bool y_up, double units_per_mm);

}  // namespace stipplot::serve
