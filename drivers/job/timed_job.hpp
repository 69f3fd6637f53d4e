#pragma once
// The timed plan of a job: when each line is done, from the job's own text and the
// machine's motion model, as a host that keeps the device fed would see it. For G-code
// the lines run through grbl's planner and stepper (drivers/motion/grbl_motion.hpp): moves
// in step units, corners at the junction speed, a sync (pen change M3/M5, G4 dwell, M0,
// M2) waits for the planner to empty and the stepper idle lock; for HPGL every point is a
// start-stop move, pens go up, down and round the carousel in fixed times.
//
// The estimate a command reports, the progress bar's ETA, and where a resume restarts
// all read these times (JobLine::done_s), so they agree with each other; the real grbl
// firmware checks them in tests/firmware.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "drivers/job/job.hpp"
#include "drivers/motion/grbl_motion.hpp"
#include "drivers/motion/hpgl_motion.hpp"

namespace stipplot::io {

struct JobTiming {
  std::vector<double> done_s;   // per line: when it is done (non-decreasing)
  double total_s = 0;           // the last line done (host pauses take no time)
  double motion_start_s = -1;   // the first move begins (-1: no move)
  double motion_end_s = -1;     // the last move ends
  size_t stops = 0;             // times the machine came to rest (grbl: each costs $1)
  double idle_lock_s = 0;       // what the stepper idle lock cost in all
  size_t pauses = 0;            // lines where the host waits for the operator
  std::vector<double> starts_from_rest;  // each time motion begins from a standstill
};

// How lines reach grbl: character counting (at most `rx_buffer` bytes of unanswered
// lines in its receive buffer) over a wire of `baud` (10 bits a byte) with a one-way
// `latency_s`. baud 0: lines arrive the moment grbl can take them.
struct GcodeLink {
  double baud = 115200;
  int rx_buffer = 128;
  double latency_s = 0;
};

// G-code through grbl's motion, streamed as `link` says, one line at a time (a writer
// can time what it writes without keeping it). Machine coordinates are the job's (G54 at
// zero). O(planner blocks) per line; keeps 8 bytes per line (when it is done).
class GcodeTimer {
 public:
  GcodeTimer(const motion::GrblSettings& machine, const GcodeLink& link = {});
  ~GcodeTimer();
  GcodeTimer(const GcodeTimer&) = delete;
  GcodeTimer& operator=(const GcodeTimer&) = delete;
  // A line as written (comments and blank lines are dropped, as grbl drops them).
  void feed(std::string_view raw_line);
  size_t lines() const;  // lines fed that grbl sees
  // Room for this many lines' times at once: a job of millions of lines then never holds
  // its times twice while they grow (untouched room is not resident). O(1).
  void reserve(size_t lines);
  JobTiming finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// HPGL with its plotter's motion, one instruction at a time. O(points) per instruction.
class HpglTimer {
 public:
  explicit HpglTimer(const motion::HpglMotion& plotter);
  // An instruction in the reader's normal form ("PD10,20;"); a pause comment (host only)
  // takes no plotter time but counts as a pause.
  void feed(std::string_view instruction, bool host_only = false, bool pause = false);
  size_t lines() const { return t_.done_s.size(); }
  void reserve(size_t lines) { t_.done_s.reserve(lines); }
  JobTiming finish() { return t_; }

 private:
  motion::HpglMotion m_;
  JobTiming t_;
  double now_ = 0, x_ = 0, y_ = 0, vs_;
  bool down_ = false, absolute_ = true;
};

// EiBotBoard commands, one line at a time: the firmware runs its FIFO back to back, so a
// line is done when every SM before it has run its milliseconds, every LM its ticks to its
// last step (the firmware's own integer arithmetic, lm_ticks) and every SP its delay (a
// host that keeps the FIFO full, as the EBB streamer does). O(1) per line (O(log ticks)
// for an LM).
class EbbTimer {
 public:
  void feed(std::string_view line, bool host_only = false, bool pause = false);
  size_t lines() const { return t_.done_s.size(); }
  void reserve(size_t lines) { t_.done_s.reserve(lines); }
  JobTiming finish() { return t_; }

 private:
  JobTiming t_;
  int64_t now_ticks_ = 0;  // the firmware's 40 µs motion ticks
  bool moving_ = false;
};

// A whole job. O(lines * planner blocks) / O(lines + points) / O(lines).
JobTiming time_gcode_job(const Job& job, const motion::GrblSettings& machine, const GcodeLink& link = {});
JobTiming time_hpgl_job(const Job& job, const motion::HpglMotion& plotter);
JobTiming time_ebb_job(const Job& job);

// Writes the timing into the job: each line's done_s and est_s, and est_total_s.
void apply_timing(Job& job, const JobTiming& t);

// The time left after line `line` is done, by the timed plan. O(1).
double seconds_after(const Job& job, long line);

}  // namespace stipplot::io
