#pragma once
// HPGL from a Plan and a device profile: IN; VS (where the profile allows it); one SP n
// per layer, n the carousel slot its pen is in (drivers/device/carousel.hpp); PU x,y to
// each stroke's start and PD with the rest of its points in chunks of at most
// max_points_per_command pairs; SP0 at the end. A plan with more pens than the carousel
// holds gets a reload pause before the layer that needs one: SP0; (stow the pen) and
// CO"stipplot pause: load pen 7 red #ff0000 in slot 1, ..."; — HP-GL/2's comment
// instruction, which the streamer recognises (hpgl_pause_message) and does not send.
// Coordinates are integer plotter units (units_per_mm) with the profile's origin and axis
// signs (y flipped for the usual lower-left origin). One command (ending in ';') a line;
// the profile's `newline` says whether a file or a device gets '\n' after each.
#include <string>
#include <vector>

#include "drivers/device/profile.hpp"
#include "drivers/writers/line_output.hpp"
#include "plan/plan.hpp"

namespace stipplot {

// Calls `sink` with each command in order. O(total points) time, O(1) extra memory.
void write_hpgl(const Plan& plan, const DeviceProfile& profile, const LineSink& sink);
std::vector<std::string> hpgl_commands(const Plan& plan, const DeviceProfile& profile);
// Atomic: the file appears whole or not at all.
void write_hpgl_file(const Plan& plan, const DeviceProfile& profile, const std::string& path);

}  // namespace stipplot
