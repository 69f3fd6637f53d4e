#pragma once
// Motion and time model: how long a plotter running grbl's planner takes to plot a
// Plan. Moves are trapezoidal velocity profiles (accelerate, cruise, decelerate);
// corners are taken at grbl's junction-deviation speed; each block's exit speed is
// planned backward from the end of a look-ahead buffer of `lookahead_blocks` blocks
// (the machine must always be able to stop at the end of what it has been sent) and
// forward from its entry speed. Pen lifts and drops flush the planner (grbl syncs on
// M3/M5/G4), so every stroke and every pen-up move starts and ends at rest.
#include <cstdint>
#include <vector>

#include "drivers/motion/motion_params.hpp"
#include "plan/plan.hpp"

namespace stipplot::motion {

enum class BlockKind : uint8_t { Travel, Draw, PenDown, PenUp };

struct MotionBlock {
  BlockKind kind;
  uint32_t layer;
  double start_s, duration_s;  // pen events: the lift/drop delay
  Vec2 from, to;               // equal for pen events
  double v_entry = 0, v_exit = 0, v_peak = 0;  // mm/s
};

struct MotionTimeline {
  std::vector<MotionBlock> blocks;   // empty unless asked for
  std::vector<double> layer_seconds; // per planned layer (its moves and pen events)
  double home_seconds = 0;           // the final return to the origin, if asked for
  double total_seconds = 0;
};

// Walks the plan from `origin` (each layer starts where the previous ended; each pen
// taken up, and the last one put away, costs m.pen_change_s).
// O(B * segments) for a look-ahead of B blocks.
MotionTimeline simulate_motion(const Plan& plan, const MotionParams& m, Vec2 origin = {0, 0},
                               bool return_home = false, bool keep_blocks = false);

// Total estimated seconds (no return home). Same cost as simulate_motion.
double estimate_seconds(const Plan& plan, const MotionParams& m);

// --- building blocks, exposed for tests and the simulator ---

// Acceleration along unit direction u when each axis is limited to `accel` (grbl's
// limit_value_by_axis_maximum): accel / max(|ux|, |uy|).
double axis_limited_accel(double accel, Vec2 u);

// Squared maximum speed through the corner from unit direction u_in to u_out, by
// grbl's junction deviation: v^2 = a * delta * sin(theta/2) / (1 - sin(theta/2)),
// theta the angle between -u_in and u_out; 0 for a full reversal, unlimited
// (infinity) straight on. Not yet capped by the blocks' nominal speeds.
double junction_speed_sqr(Vec2 u_in, Vec2 u_out, const MotionParams& m);

// Time of one trapezoidal (or triangular, if too short to cruise) move of length L
// from speed v0 to v1 with cruise speed vmax and acceleration a. Requires
// |v1^2 - v0^2| <= 2 a L and v0, v1 <= vmax. Sets *v_peak if given.
double trapezoid_seconds(double L, double v0, double v1, double vmax, double a, double* v_peak = nullptr);

// Seconds to run the connected polyline pts at cruise speed vmax, from rest to rest,
// with look-ahead over m.lookahead_blocks. Appends blocks if out is given.
double polyline_seconds(const std::vector<Vec2>& pts, double vmax, const MotionParams& m,
                        std::vector<MotionBlock>* out = nullptr, BlockKind kind = BlockKind::Draw, uint32_t layer = 0,
                        double t0 = 0);

}  // namespace stipplot::motion

namespace stipplot {
using motion::estimate_seconds;
using motion::simulate_motion;
}  // namespace stipplot
