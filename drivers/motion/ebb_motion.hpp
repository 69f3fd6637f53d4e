#pragma once
// An EiBotBoard machine's motion: two motors mixed (motor 1 = x + y, motor 2 = x - y, in
// motor steps of 1/steps_per_mm mm of each sum), one step at most per 40 µs tick of the
// firmware's 25 kHz motion interrupt. The host plans the acceleration: a timed path
// (polyline_seconds' trapezoids, corners at the junction speed) becomes either
//  - LM moves (the default, firmware 2.7+): each trapezoid's accelerate, cruise and
//    decelerate phases one LM each, whose per-tick rate and rate change the firmware
//    integrates itself, so the motors follow the plan's speed ramps; or
//  - SM moves: sampled at its vertices and at most every slice, each move between samples
//    one constant-rate SM of whole milliseconds.
// Every phase end or sample is rounded to whole motor steps from the machine's zero (so
// rounding never accumulates: the pen ends where the plan says, to half a step).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drivers/motion/time_model.hpp"

namespace stipplot::motion {

using MotorSteps = std::array<int64_t, 2>;

struct EbbGeometry {
  double steps_per_mm = 80;
  // Nearest motor steps of a machine position (mm).
  MotorSteps steps(Vec2 mm) const;
  // The machine position of motor steps (mm).
  Vec2 mm(const MotorSteps& s) const;
};

// One motion command: an SM of `ms` milliseconds, or (lm) an LM, each motor's steps
// (signed) and, for an LM, each motor's rate and per-tick rate change in the firmware's
// units (2^31 is one step per tick), counted towards its steps' sign: the firmware's
// legacy form, which 2.7 and 3.x read alike (negative steps flip rate and accel).
struct EbbMove {
  int64_t ms = 0;
  int64_t s1 = 0, s2 = 0;
  bool lm = false;
  int64_t r1 = 0, a1 = 0, r2 = 0, a2 = 0;
};

// Which command the writer cuts the plan into ([ebb] moves).
enum class EbbMoveKind { lm, sm };
struct EbbMoveSettings {
  EbbMoveKind kind = EbbMoveKind::lm;
  int slice_ms = 25;  // SM only
};

// The firmware's limits on one SM: a duration of 1 ms or more, and at most 25 steps per
// ms on either motor (its rate accumulator overflows past that: "step rate too high").
constexpr int64_t kEbbStepsPerMs = 25;
bool ebb_move_ok(const EbbMove& m);
// The move as the firmware's command: "SM,<ms>,<steps 1>,<steps 2>".
std::string sm_command(const EbbMove& m);
// "LM,<r1>,<s1>,<a1>,<r2>,<s2>,<a2>,3" for an LM (3: both accumulators cleared, so its
// time is its own: lm_ticks), sm_command otherwise.
std::string ebb_command(const EbbMove& m);

// The LM's arithmetic, as the firmware's ISR does it (ebb.c; plotink's move_dist_lt): one
// motor of a cleared LM with rate r and accel a (towards its steps) has, after n ticks,
// accumulated n * (r - trunc(a / 2)) + a * n * (n + 1) / 2, a step per 2^31.
constexpr int64_t kEbbTicksPerS = 25000;
constexpr int64_t kEbbOneStep = int64_t{1} << 31;
// The rate the motor steps at on tick n (1 is the first). O(1).
int64_t lm_rate(int64_t r, int64_t a, int64_t n);
// The tick on which one motor of a cleared LM makes its last of `steps` (>= 0) steps: 0
// for none, -1 if it never does (its rate falls to 0 first, or starts at 0). O(1).
int64_t lm_motor_ticks(int64_t steps, int64_t r, int64_t a);
// The firmware's time of an LM (the later motor), -1 if a motor never ends. O(1).
int64_t lm_ticks(const EbbMove& m);
// Whether the firmware runs the LM as planned: each motor's rate within (0, 2^31) from its
// first tick to its last step (never reversing or stalling), and some motor moving. O(1).
bool lm_ok(const EbbMove& m);
// One LM phase: motor steps s1, s2 in about `ticks` ticks, the speed going linearly from
// v0 to v1 (any unit; only their ratio counts). Each motor's accel is the shape's, and its
// rate the least that makes its last step come by the phase's last tick, so both end
// together. Lengthened when a motor would pass one step per tick; nullopt when no LM
// fits (a phase of no step, or one the firmware cannot run). O(1).
std::optional<EbbMove> lm_phase(int64_t s1, int64_t s2, int64_t ticks, double v0, double v1);

// Cuts timed blocks (machine mm, planned with acceleration accel_mm_s2, back to back from rest to rest, as polyline_seconds gives
// them) into SM moves of at most slice_ms, starting from motor position `at` and
// millisecond `clock_ms` (both advanced). Sample times are rounded to whole ms on the
// job's clock, so durations do not drift either; a sample less than 1 ms after the one
// before is pushed to 1 ms, and a move that would step faster than the firmware allows is
// lengthened. O(blocks + moves).
void slice_blocks(const std::vector<MotionBlock>& blocks, const EbbGeometry& g, double accel_mm_s2, int slice_ms, MotorSteps& at,
                  int64_t& clock_ms, std::vector<EbbMove>& out);

// Turns timed blocks (as slice_blocks takes them) into LM moves: each block's accelerate,
// cruise and decelerate phases (of its trapezoid at axis_limited_accel) one LM each (one
// LM for the block when a single ramp from its entry to its exit speed, scaled to its
// time, changes those speeds by at most 5 % of its peak speed), each phase's
// end rounded to whole motor steps from the machine's zero and its end time to whole
// ticks on the job's clock `clock_ticks` (advanced by each LM's firmware time, lm_ticks,
// so durations do not drift either). A phase of no whole step gives its time to the next
// one; a phase no LM fits (lm_phase) becomes an SM. O(blocks).
void lm_blocks(const std::vector<MotionBlock>& blocks, const EbbGeometry& g, double accel_mm_s2, MotorSteps& at,
               int64_t& clock_ticks, std::vector<EbbMove>& out);

// A polyline from rest to rest as LM or SM moves: planned by polyline_seconds at cruise
// speed vmax with the machine's motion, then cut by lm_blocks or slice_blocks (the
// writer's strokes and travels, and a resume's moves). `clock_ticks` is the job's clock
// in ticks (25 a millisecond). `blocks` is scratch space. O(points + moves).
void polyline_moves(const std::vector<Vec2>& pts, double vmax, const MotionParams& m, const EbbGeometry& g,
                    const EbbMoveSettings& how, MotorSteps& at, int64_t& clock_ticks, std::vector<MotionBlock>& blocks,
                    std::vector<EbbMove>& out);

// Distance along a trapezoidal block at time t after its start (0 <= t <= duration),
// with acceleration a (as polyline_seconds profiled it). O(1).
double block_distance(const MotionBlock& b, double a, double t);

}  // namespace stipplot::motion
