#pragma once
// grbl 1.1's motion, as its planner.c and stepper.c do it: moves are quantised to whole
// steps ($100-$102), each block's speed and acceleration are limited per axis ($110-$112,
// $120-$122) along its direction, corners are taken at the junction-deviation speed ($11)
// with the per-axis acceleration along the junction vector, a planner of 15 blocks is
// re-planned (reverse then forward pass) every time a block is added, the newest block
// always ends at rest, a block added to an empty planner starts from rest, and every time
// the machine stops the stepper idle lock ($1) holds grbl for its milliseconds. The block
// under way is re-profiled from its current speed when the plan changes, as the stepper's
// segment preparation does. At a stop the stepper interrupt notices the empty segment
// buffer one timer period after the last step, and it wakes up again one (old) period
// late: two periods of the final 10 ms segment per standstill.
//
// GrblMotion runs that machine in continuous time: the simulated grbl drives it from the
// lines it receives, and the job timer (drivers/job/timed_job.hpp) from a job, as a host
// that keeps the planner full would.
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <limits>
#include <vector>

namespace stipplot::motion {

using Vec3 = std::array<double, 3>;  // x, y, z in mm

// The machine settings the motion depends on, with grbl's numbers.
struct GrblSettings {
  Vec3 steps_per_mm{100, 100, 100};            // $100-$102
  Vec3 max_rate_mm_min{9000, 9000, 9000};      // $110-$112
  Vec3 accel_mm_s2{1000, 1000, 1000};          // $120-$122
  double junction_deviation_mm = 0.01;         // $11
  double idle_lock_s = 0.025;                  // $1 (255 = keep the steppers on: no wait)
  int planner_blocks = 15;                     // BLOCK_BUFFER_SIZE - 1 on a 328p
  // $1 in milliseconds as grbl stores it: 255 means no wait.
  static double idle_lock_from_setting(double ms) { return ms >= 255 ? 0 : ms / 1000; }
};

// grbl's dwell (G4 P): a whole number of 50 ms steps, rounded up, computed in single
// precision as grbl's delay_sec() does.
double grbl_dwell_seconds(double p);

// A planner block: a straight move between step positions.
struct GrblBlock {
  std::array<int64_t, 3> from{}, to{};  // steps
  Vec3 unit{};                          // direction
  double mm = 0;                        // length from the step positions
  double accel = 0;                     // mm/s^2 along the move (per-axis limited)
  double nominal = 0;                   // mm/s: programmed rate, limited per axis
  double max_entry_sqr = 0;             // (mm/s)^2: junction and nominal limits
  double entry_sqr = 0;                 // as planned
  bool rapid = false;
  long tag = -1;                        // the caller's: a line number
  Vec3 target{};                        // as programmed, before rounding to steps
};

// Runs blocks through grbl's planner and stepper. Times are seconds on the caller's
// clock; advance() moves the machine to a time, next_event() says when something next
// changes by itself. O(planner size) per block planned.
class GrblMotion {
 public:
  explicit GrblMotion(const GrblSettings& s);
  const GrblSettings& settings() const { return s_; }

  // The planner has room for another block.
  bool has_room() const { return static_cast<int>(blocks_.size()) < s_.planner_blocks; }
  // Plans a move to `target` (machine mm) at `feed_mm_min`, or at the axes' rates when
  // `rapid`, at time t (now, after advance(t)). False when the move makes no step (grbl
  // drops it). Requires has_room().
  bool plan(const Vec3& target, double feed_mm_min, bool rapid, long tag, double t);
  // Runs the machine up to time t (>= the last time given).
  void advance(double t);
  // When the running block ends or the idle lock is over; +inf when nothing runs.
  double next_event() const;

  bool moving() const { return !blocks_.empty() && !hold_stopped_; }
  // Moving, or waiting out the stepper idle lock: a line that syncs must wait.
  bool busy() const { return moving() || idle_until_ > now_; }
  size_t planned() const { return blocks_.size(); }  // blocks in the planner, the running one too
  const std::deque<GrblBlock>& blocks() const { return blocks_; }
  Vec3 position() const;         // where the tool is now (mm)
  double speed() const { return hold_stopped_ ? 0 : v_; }
  std::array<int64_t, 3> planner_steps() const { return planner_pos_; }

  // Feed hold: decelerate at the blocks' accelerations and stop; resume() goes on from
  // rest. hold_complete(): stopped in the hold.
  void hold(double t);
  void resume(double t);
  bool holding() const { return hold_; }
  bool hold_complete() const { return hold_ && (hold_stopped_ || blocks_.empty()); }
  // Reset or alarm: motion stops where it is, the planner is emptied, the position is
  // kept (grbl's step counters), the idle lock is not waited.
  void halt();
  // The machine is at `mm` (homing, power-on): planner and stepper start from there.
  void set_position(const Vec3& mm);

  // Blocks that ran to their end since the last call.
  struct Finished {
    long tag;
    double t;
    Vec3 end;     // in whole steps
    Vec3 target;  // as programmed
  };
  std::vector<Finished> take_finished();
  // grbl's main loop is held by the idle lock until then (it parses nothing meanwhile).
  bool in_idle_lock(double t) const { return blocks_.empty() && t < idle_until_; }
  // Seconds the idle lock has cost so far, and how many times the machine stopped.
  double idle_lock_total_s() const { return idle_total_; }
  size_t stops() const { return stops_; }
  // When the first block began to move (-1 before any), and every start from rest.
  double first_motion_s() const { return first_start_; }
  const std::vector<double>& starts_from_rest() const { return rest_starts_; }

 private:
  void replan();
  void profile_current();  // the running block from its current speed to its exit
  double exit_sqr_of_current() const;
  void finish_current(double t);
  double limit_by_axes(const Vec3& values, const Vec3& unit) const;

  GrblSettings s_;
  std::deque<GrblBlock> blocks_;
  std::array<int64_t, 3> planner_pos_{};  // end of the last planned block (steps)
  Vec3 prev_unit_{};
  double prev_nominal_ = 0;
  // The running block: distance done, speed now, and its profile from `seg_t0_`.
  double done_mm_ = 0, v_ = 0;
  struct Phase {
    double t, a, v0, dist;  // duration, acceleration (signed), start speed, distance covered
  };
  std::vector<Phase> phases_;
  double seg_t0_ = 0, seg_mm0_ = 0;
  double now_ = 0;
  double idle_until_ = -std::numeric_limits<double>::infinity();
  double idle_total_ = 0, first_start_ = -1;
  size_t stops_ = 0;
  bool hold_ = false, hold_stopped_ = false;
  std::vector<Finished> finished_;
  std::vector<double> rest_starts_;
  double last_tick_s_ = 0;  // the stepper timer's period when the machine last stopped
  double start_not_before_ = 0;  // a block planned into an empty planner moves from then
  Vec3 rest_pos_{};  // machine position while no block runs
};

}  // namespace stipplot::motion
