#include "drivers/stream/grbl/codes.hpp"

#include <map>

namespace stipplot::io::grbl {

std::string error_meaning(int code) {
  static const std::map<int, const char*> t = {
      {1, "Expected command letter: G-code words consist of a letter and a value. Letter was not found."},
      {2, "Bad number format: missing the expected G-code word value or numeric value format is not valid."},
      {3, "Invalid statement: grbl '$' system command was not recognized or supported."},
      {4, "Value < 0: negative value received for an expected positive value."},
      {5, "Setting disabled: homing cycle failure. Homing is not enabled via settings."},
      {6, "Value < 3 usec: minimum step pulse time must be greater than 3 usec."},
      {7, "EEPROM read fail: an EEPROM read failed. Auto-restoring affected EEPROM to default values."},
      {8, "Not idle: grbl '$' command cannot be used unless grbl is IDLE."},
      {9, "G-code lock: G-code commands are locked out during alarm or jog state."},
      {10, "Homing not enabled: soft limits cannot be enabled without homing also enabled."},
      {11, "Line overflow: max characters per line exceeded. The line was not executed."},
      {12, "Step rate > 30kHz: a '$' setting value causes the step rate to exceed the maximum supported."},
      {13, "Check door: safety door detected as opened and door state initiated."},
      {14, "Line length exceeded: build info or startup line exceeded EEPROM line length limit."},
      {15, "Travel exceeded: jog target exceeds machine travel. Jog command has been ignored."},
      {16, "Invalid jog command: jog command has no '=' or contains prohibited g-code."},
      {17, "Setting disabled: laser mode requires PWM output."},
      {20, "Unsupported command: unsupported or invalid g-code command found in block."},
      {21, "Modal group violation: more than one g-code command from same modal group found in block."},
      {22, "Undefined feed rate: feed rate has not yet been set or is undefined."},
      {23, "G-code command in block requires an integer value."},
      {24, "More than one g-code command that requires axis words found in block."},
      {25, "Repeated g-code word found in block."},
      {26, "No axis words found in block for g-code command or current modal state which requires them."},
      {27, "Line number value is invalid."},
      {28, "G-code command is missing a required value word."},
      {29, "G59.x work coordinate systems are not supported."},
      {30, "G53 only allowed with G0 and G1 motion modes."},
      {31, "Axis words found in block when no command or current modal state uses them."},
      {32, "G2 and G3 arcs require at least one in-plane axis word."},
      {33, "Motion command target is invalid."},
      {34, "Arc radius value is invalid."},
      {35, "G2 and G3 arcs require at least one in-plane offset word."},
      {36, "Unused value words found in block."},
      {37, "G43.1 dynamic tool length offset is not assigned to configured tool length axis."},
      {38, "Tool number greater than max supported value."},
  };
  auto it = t.find(code);
  return it != t.end() ? it->second : "unknown grbl error code " + std::to_string(code);
}

std::string alarm_meaning(int code) {
  static const std::map<int, const char*> t = {
      {1, "Hard limit: a limit switch was triggered. Machine position is likely lost; re-homing is recommended."},
      {2, "Soft limit: a motion target exceeds the machine travel. Machine position retained; the alarm may be "
          "safely unlocked ($X)."},
      {3, "Abort during cycle: reset while in motion. Machine position is likely lost; re-homing is recommended."},
      {4, "Probe fail: the probe is not in the expected initial state before starting the probe cycle."},
      {5, "Probe fail: the probe did not contact the workpiece within the programmed travel."},
      {6, "Homing fail: the active homing cycle was reset."},
      {7, "Homing fail: safety door was opened during the homing cycle."},
      {8, "Homing fail: pull-off travel failed to clear the limit switch."},
      {9, "Homing fail: could not find the limit switch within the search distance."},
      {10, "Homing fail: on dual-axis machines, could not find the second limit switch for self-squaring."},
  };
  auto it = t.find(code);
  return it != t.end() ? it->second : "unknown grbl alarm code " + std::to_string(code);
}

}  // namespace stipplot::io::grbl
