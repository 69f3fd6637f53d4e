#pragma once
// Where and how to continue a job after line `next - 1` was the last one done.
#include <string>
#include <vector>

#include "drivers/job/job.hpp"

namespace stipplot::io {

struct ResumePlan {
  size_t next = 0;                    // first job line to send after the preamble
  std::vector<std::string> preamble;  // lines to send first
};

// What the device reports about its pen, when it can (grbl: spindle speed and Z from a
// status report).
struct DevicePen {
  bool known = false, down = false;
  double x = 0, y = 0;
};

// Restores units/modes and the feed, lifts the pen, travels to where line `next - 1`
// ended, and puts the pen in the state it had. A resume point just after a pen-down
// that has not moved yet is moved: past the pen-up of a dot (the lift finished it), or
// back to the pen-down of a stroke. If the device's pen is already where and as it
// should be (the device kept running after the link dropped), nothing is lifted or
// moved. Throws UserError for a job it cannot resume (G91, no pen-up command).
// O(job size).
ResumePlan plan_resume(const Job& job, size_t next, const DevicePen& device = {});

}  // namespace stipplot::io
