#pragma once
// Resuming an EBB job on a board that was reset (power cycle, reboot) mid-plot: its step
// counters restart at 0 and its motion FIFO is gone, so the board cannot say where it
// stopped. What it ran is known from the journal: every line before the last `fifo + 1`
// queued commands it had acknowledged surely ran (an OK means queued; the FIFO holds at
// most `fifo` commands and the motion interrupt one more), and a QS answered while
// plotting proved the carriage stood at a point of a move (streamer.cpp journals it as a
// ProvenPoint). The resume starts at the later of the two, splitting an SM or LM at a
// proven point; the carriage is taken to be at home (0,0), where the board's counters restart.
#include <array>
#include <cstdint>

#include "drivers/device/profile.hpp"
#include "drivers/job/job.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/resume.hpp"

namespace stipplot::io::ebb {

using Steps = std::array<int64_t, 2>;

// Motor steps where job line `i` leaves the carriage (0,0 before the first line).
Steps steps_after(const Job& job, long i, double spm);

// The part of an SM (ms, s1, s2) left to run once `done` steps of it were made: the
// remaining steps exactly (done + rest = the SM's own steps, so nothing drifts) and the
// duration in proportion to the remaining share of its larger motor's steps, at least
// 1 ms and never faster than the firmware's 25 steps per ms. O(1).
struct SmPart {
  int64_t ms = 0, s1 = 0, s2 = 0;
};
SmPart sm_remainder(int64_t ms, int64_t s1, int64_t s2, const Steps& done);

// Whether motor position `at` lies on job line i's SM or LM path: each motor steps at its
// own constant rate (an LM's: on one shared speed ramp), so at some share t in [0, 1] of
// the move motor k stands within a step or so of
// t * s_k. A line that does not move holds nothing. O(1).
bool on_sm_path(const Job& job, size_t i, const Steps& at, double spm);

// The first line in [from, to] whose SM path holds `at`, -1 if none: at a crossing (or a
// vertex, the end of one move and the start of the next) the earlier, so a proof never
// claims more than was drawn. O(to - from).
long first_on_path(const Job& job, size_t from, size_t to, const Steps& at, double spm);

// The first line the board may not have run when it held commands up to `last` queued:
// the line of the (fifo + 1)-th command going back from `last` that takes a place in the
// FIFO (SM, LM, SP, EM; other commands run as they are parsed). 0 when there are fewer.
// O(fifo + lines between).
size_t first_unsure(const Job& job, long last, int fifo);

// The plan for a reset board (its QS read 0,0 and matched nothing): from the journal's
// last proof when it is at or after first_unsure(last acknowledged), its SM split there
// when the proof lies inside a pen-down move; else from first_unsure; past acknowledged
// lines that neither move nor leave the pen down (a pause counted as done). The preamble: the
// job's own lines before its first move (EM, SC servo settings, pen up), the pen up, an
// accelerated travel from home to the resume point (the profile's pen-up speed and
// acceleration, cut into LMs or SMs as the writer cuts them: LMs when the job has any),
// the job's own pen-down when the pen was down there, and the rest of a split move: an
// SM's remaining steps in its remaining time, or an LM's rest planned again from rest to
// its end at the pen-down speed (its ramp cannot be cut mid-way). `redraw` is the most pen-down path (mm)
// it may draw again. O(job size).
ResumePlan plan_reset_resume(const Job& job, const JournalState& journal, const DeviceProfile& profile, int fifo);

}  // namespace stipplot::io::ebb
