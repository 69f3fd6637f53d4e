#pragma once
// EiBotBoard commands from a Plan and an EBB profile (AxiDraw): the whole job is the
// firmware's own commands, one a line, so a streamer sends them as they are and the job
// file times itself (every SM, LM and SP says how long it takes).
//   EM,1,1                  motors on at 16x microstepping; the position is zeroed there
//   SC,4,.. SC,5,.. SC,11,.. SC,12,..  the pen's up/down positions and rates (axicli's)
//   SC,8,1                  a brushless pen lift only: one servo PWM channel
//   SP,1,<raise_ms>         pen up (SP,1,<raise_ms>,2 on a brushless lift's pin RB2)
//   per stroke: LM,<r1>,<m1>,<a1>,<r2>,<m2>,<a2>,3 ... travel (pen up; SM,<ms>,<m1>,<m2>
//   with [ebb] moves = "sm"), SP,0,<lower_ms>, LM ... the
//   stroke at pen-down speed, SP,1,<raise_ms>; a one-point stroke is a touch
//   at the end: travel back to machine zero (the home corner).
// Moves are planned with the profile's motion (accelerations, corner speeds) and cut into
// LM phases or SM slices by drivers/motion/ebb_motion.hpp. Between layers a host-only line
// "# pause: Change pen: ..." (never sent) is where the streamer waits for the operator.
#include <functional>
#include <string>
#include <vector>

#include "drivers/device/profile.hpp"
#include "drivers/writers/line_output.hpp"
#include "plan/plan.hpp"

namespace stipplot {

struct EbbOptions {
  LineSink also;                               // every line as it is written
  std::function<void(size_t layer)> on_layer;  // before each layer's first line
};

// Calls `sink` with each line in order; throws UserError for a plan outside the
// machine's travel, before the first line. O(total points + moves).
void write_ebb(const Plan& plan, const DeviceProfile& profile, const LineSink& sink, const EbbOptions& opt = {});
std::vector<std::string> ebb_commands(const Plan& plan, const DeviceProfile& profile);
// Atomic: the file appears whole or not at all.
void write_ebb_file(const Plan& plan, const DeviceProfile& profile, const std::string& path, const EbbOptions& opt = {});

}  // namespace stipplot
