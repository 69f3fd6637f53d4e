#pragma once
// An EiBotBoard machine's motion: two motors mixed (motor 1 = x + y, motor 2 = x - y, in
// motor steps of 1/steps_per_mm mm of each sum), moved by the firmware's SM command, which
// steps each motor at a constant rate for a whole number of milliseconds (one step at most
// per 40 µs tick of its 25 kHz motion interrupt: 25 steps per ms). The host plans the
// acceleration: a timed path (polyline_seconds' trapezoids, corners at the junction speed)
// is sampled at its vertices and at most every slice, each sample rounded to whole motor
// steps from the machine's zero (so rounding never accumulates: the pen ends where the
// plan says, to half a step), and every move between samples becomes one SM.
#include <array>
#include <cstdint>
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

// One SM command: `ms` milliseconds, each motor's steps (signed).
struct EbbMove {
  int64_t ms = 0;
  int64_t s1 = 0, s2 = 0;
};

// The firmware's limits on one SM: a duration of 1 ms or more, and at most 25 steps per
// ms on either motor (its rate accumulator overflows past that: "step rate too high").
constexpr int64_t kEbbStepsPerMs = 25;
bool ebb_move_ok(const EbbMove& m);
// The move as the firmware's command: "SM,<ms>,<steps 1>,<steps 2>".
std::string sm_command(const EbbMove& m);

// Cuts timed blocks (machine mm, planned with acceleration accel_mm_s2, back to back from rest to rest, as polyline_seconds gives
// them) into SM moves of at most slice_ms, starting from motor position `at` and
// millisecond `clock_ms` (both advanced). Sample times are rounded to whole ms on the
// job's clock, so durations do not drift either; a sample less than 1 ms after the one
// before is pushed to 1 ms, and a move that would step faster than the firmware allows is
// lengthened. O(blocks + moves).
void slice_blocks(const std::vector<MotionBlock>& blocks, const EbbGeometry& g, double accel_mm_s2, int slice_ms, MotorSteps& at,
                  int64_t& clock_ms, std::vector<EbbMove>& out);

// A polyline from rest to rest as SM moves: planned by polyline_seconds at cruise speed
// vmax with the machine's motion, then cut by slice_blocks (the writer's strokes and
// travels, and a resume's travel from home). `blocks` is scratch space. O(points + moves).
void polyline_moves(const std::vector<Vec2>& pts, double vmax, const MotionParams& m, const EbbGeometry& g, int slice_ms,
                    MotorSteps& at, int64_t& clock_ms, std::vector<MotionBlock>& blocks, std::vector<EbbMove>& out);

// Distance along a trapezoidal block at time t after its start (0 <= t <= duration),
// with acceleration a (as polyline_seconds profiled it). O(1).
double block_distance(const MotionBlock& b, double a, double t);

}  // namespace stipplot::motion
