#pragma once
// A plot job as the streamers see it: text lines (G-code lines or HPGL instructions),
// each with what it does to the pen and where the pen is after it, read from the job
// text itself (gcode_reader.hpp, hpgl_reader.hpp), and the segments a job draws.
#include <string>
#include <vector>

namespace stipplot::io {

enum class Dialect { GCode, Hpgl };
const char* to_string(Dialect d);

struct JobLine {
  std::string text;       // one G-code line / one HPGL instruction, no terminator
  bool motion = false;    // moves the tool
  bool pen_down = false;  // pen state after the line
  double x = 0, y = 0;    // position after the line (mm for G-code, plotter units for HPGL)
  double est_s = 0;       // rough duration (distance / feed), for the ETA
};

struct Job {
  Dialect dialect = Dialect::GCode;
  std::vector<JobLine> lines;
  double est_total_s = 0;
};

// A pen-down move, or a touch (x0 == x1, y0 == y1): what a plotter's record holds.
struct Segment {
  double x0, y0, x1, y1;
  int pen = 1;  // HPGL pen number (1 for G-code)
  friend bool operator==(const Segment&, const Segment&) = default;
};

}  // namespace stipplot::io
