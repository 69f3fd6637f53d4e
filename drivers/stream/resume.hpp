#pragma once
// Where and how to continue a job after line `next - 1` was the last one done.
#include <string>
#include <vector>

#include "drivers/job/job.hpp"
#include "drivers/stream/journal.hpp"

namespace stipplot::io {

struct ResumePlan {
  size_t next = 0;                    // first job line to send after the preamble
  std::vector<std::string> preamble;  // lines to send first
  std::string note;                   // why it is not the line after the journal's last, if it is not
  // The most pen-down path it may draw again (job units: mm, HPGL plotter units), and why
  // it starts there (resume_from_journal only).
  double redraw = 0;
  std::string why;
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

// Continues inside job line `line` from (x, y), a point on its path: travels there pen up,
// puts the pen down, and sends the line itself (absolute, so it draws from there to its
// end). A line that draws nothing resumes from its start (plan_resume). O(job size).
ResumePlan plan_resume_within(const Job& job, size_t line, double x, double y);

// How far the device may be from the journal when the host did not stop it (killed,
// link lost): lines it may have run that the journal never heard of (its receive buffer
// holds at most `ahead_bytes`), and acknowledged moves it may never have run (its
// planner, up to `back_moves`, when its buffers were lost since).
struct ResumeWindow {
  size_t ahead_bytes = 0;
  size_t back_moves = 0;
  size_t line_end_bytes = 1;  // what ends a line on the wire ('\n'; none between HPGL instructions)
  // Acknowledged lines within this many bytes of the journal's end may never have run on
  // a device that came back fresh: an HPGL plotter paced by XON/XOFF or RTS/CTS, whose
  // acknowledgement is the write, loses its buffer with the power.
  size_t unproven_bytes = 0;
  // Acknowledged moves a device that came back fresh (its pen matching nothing the journal
  // allows) may never have run, whether or not it was seen to restart: grbl answers a
  // line once it is in the planner, and a board whose reset went unseen (no banner: the
  // port opened after it) lost its planner all the same.
  size_t fresh_back_moves = 0;
};

// The first line to resume from. After a stop that dropped the device's buffers (the
// journal says so), the line after the last acknowledged; otherwise the first line of
// the window from which the device's pen, as it is now, continues: the pen where and as
// the line before leaves it, or on the line's own path (begun, not finished). Earlier
// rather than later when lines end alike: a move drawn twice, never one lost. With
// nothing matching, the window's first line. O(window).
size_t resume_point(const Job& job, const JournalState& journal, const DevicePen& device, const ResumeWindow& window);

// What `plot --resume` does once the device is connected and idle: resume_point, then
// plan_resume from there. A device whose pen matches nothing there, that may have lost
// its planner and stands at machine zero, or (unproven_bytes) cannot say, came back
// fresh (a power loss: position gone or re-zeroed): it resumes from the journal's last
// proof (a status report's position, the line split there; for HPGL only an
// instruction's start or end) when that is consistent and not before the first line the
// device may not have run (fresh_back_moves moves, unproven_bytes bytes back), else
// from that line. The plan says how much pen-down path it may draw again and why.
// O(window + job size).
ResumePlan resume_from_journal(const Job& job, const JournalState& journal, const DevicePen& device = {},
                               const ResumeWindow& window = {});

}  // namespace stipplot::io
