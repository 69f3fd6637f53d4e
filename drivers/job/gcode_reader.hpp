#pragma once
// Reads a G-code job: splits it into lines (comments and blank lines dropped) and tracks
// the pen state and position after each line. The word lexer and the modal state are
// exposed for resume planning, which replays a job's modes up to a line.
#include <string>
#include <vector>

#include "drivers/job/job.hpp"

namespace stipplot::io {

// How a G-code job puts its pen down: servo or laser (M3/M4 with S > 0 down, M5 or S0
// up; a servo whose "up" is M3 S<servo_up_s> is up at that S) or a Z axis (Z below
// `z_down_below` down).
struct GcodePenRule {
  double z_down_below = 0;
  double servo_up_s = 0;  // 0: no "up" S value (up is M5 or S0)
};
bool gcode_pen_down(bool spindle_on, double s, double z, const GcodePenRule& rule);

// O(text length).
Job parse_gcode_job(const std::string& text, const GcodePenRule& rule = {});
// A raw line as the job keeps it: ( ) and ';' comments, '\r' and outer blanks dropped
// ("" for a comment or blank line).
std::string gcode_line_text(const std::string& raw);

// A letter and its number ("X12.5"); '$' system commands and '%' tape marks have none.
struct GcodeWord {
  char letter;
  double value;
};
std::vector<GcodeWord> gcode_words(const std::string& line);
// G4: a dwell.
bool is_dwell(const GcodeWord& w);

// The modes G words set: units (G20/G21), distance mode (G90/G91), motion (G0/G1).
struct GcodeModes {
  double scale = 1;  // mm per program unit (G20: 25.4)
  bool absolute = true;
  int motion = 0;  // 0 or 1
  // Applies a G word; false if it sets none of these modes.
  bool apply(const GcodeWord& g);
};

}  // namespace stipplot::io
