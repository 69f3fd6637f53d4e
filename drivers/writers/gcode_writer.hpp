#pragma once
// G-code for grbl from a Plan and a device profile: G21 G90 G94 header, G0 travel with
// the pen up, G1 drawing with the profile's feed (mm/min), the profile's pen method
// (servo M3 S../M5, Z axis, or laser M4 S../M5), G4 dwells after pen moves, and an
// M0 pause with a message naming the pen's number, name and colour at every pen change
// (M0 (MSG,Change pen: pen 2 red #ff0000), which grbl shows and a streamer prompts at). Coordinates are in machine space (origin,
// axis signs and offset from the profile) rounded to the profile's resolution; a plan
// that leaves the travel is refused before the first line is produced.
#include <string>
#include <vector>

#include "drivers/device/profile.hpp"
#include "drivers/writers/line_output.hpp"
#include "plan/plan.hpp"

namespace stipplot {

struct GcodeOptions {
  bool comments = true;  // ';' comments naming the job and layers
};

// Calls `sink` with each line in order. O(total points) time, O(1) extra memory.
void write_gcode(const Plan& plan, const DeviceProfile& profile, const LineSink& sink, const GcodeOptions& opt = {});
std::vector<std::string> gcode_lines(const Plan& plan, const DeviceProfile& profile, const GcodeOptions& opt = {});
// Atomic: the file appears whole or not at all.
void write_gcode_file(const Plan& plan, const DeviceProfile& profile, const std::string& path,
                      const GcodeOptions& opt = {});

}  // namespace stipplot
