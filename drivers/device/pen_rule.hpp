#pragma once
// How this device's G-code says the pen is down, for reading a job's pen state (and
// for the simulator, which must agree on it).
#include "drivers/device/profile.hpp"
#include "drivers/job/gcode_reader.hpp"

namespace stipplot {

// Servo: down while the spindle runs with S > 0, up at M5 or S<servo_up_s>; Z axis:
// down below the middle of its up and down heights; laser: down while it burns.
// Throws UserError for a Z profile whose down height is not below its up height.
io::GcodePenRule gcode_pen_rule(const DeviceProfile& p);

}  // namespace stipplot
