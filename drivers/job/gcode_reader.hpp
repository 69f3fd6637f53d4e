#pragma once
// Reads a G-code job: splits it into lines (comments and blank lines dropped) and tracks
// the pen state and position after each line. The word lexer and the modal state are
// exposed for resume planning, which replays a job's modes up to a line.
#include <string>
#include <string_view>
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
// A raw line as the job keeps it, as a view: ( ) and ';' comments, '\r' and outer blanks
// dropped ("" for a comment or blank line); into `raw` itself when it has no comment or
// '\r' (a writer's lines), else into `scratch`. No allocation for a plain line. O(length).
std::string_view gcode_line_view(std::string_view raw, std::string& scratch);

// A letter and its number ("X12.5"); '$' system commands and '%' tape marks have none.
struct GcodeWord {
  char letter;
  double value;
};
std::vector<GcodeWord> gcode_words(std::string_view line);
// Calls f(word) for each word of a cleaned line in order, allocating nothing (the job
// timer reads millions of lines). A line with '$' or '%' has none, as in gcode_words.
template <class F>
void for_each_gcode_word(std::string_view line, F&& f);
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

namespace detail {
// A word's number as written ("12.5", "-3", "+.5", "1 2.5" with blanks inside); 0 when
// it is none (as strtod gives). O(length).
double gcode_number(std::string_view digits);
// The next word from line[i] on, i past it; false at the line's end.
bool gcode_word_scan(std::string_view line, size_t& i, GcodeWord& w);
}  // namespace detail

template <class F>
void for_each_gcode_word(std::string_view line, F&& f) {
  if (line.find_first_of("$%") != std::string_view::npos) return;  // system command or tape marker
  size_t i = 0;
  GcodeWord w{};
  while (detail::gcode_word_scan(line, i, w)) f(w);
}

}  // namespace stipplot::io
