#pragma once
// A plot job as the streamers see it: text lines (G-code lines, HPGL instructions or
// EiBotBoard commands),
// each with what it does to the pen and where the pen is after it, read from the job
// text itself (gcode_reader.hpp, hpgl_reader.hpp), and the segments a job draws.
#include <string>
#include <vector>

namespace stipplot::io {

enum class Dialect { GCode, Hpgl, Ebb };
const char* to_string(Dialect d);

struct JobLine {
  std::string text;       // one G-code line / one HPGL instruction, no terminator
  bool motion = false;    // moves the tool
  bool pen_down = false;  // pen state after the line
  double x = 0, y = 0;    // position after the line (mm for G-code, plotter units for HPGL)
  double est_s = 0;       // its share of the job's time: done_s minus the previous line's
  double done_s = 0;      // when it is done, seconds from the start (the timed plan)
  // The host waits for the operator here (G-code M0/M1, HPGL's reload pause comment):
  // `note` says what to do ("Change pen: layer 2 red #ff0000").
  bool pause = false;
  bool host_only = false;  // not sent to the device (HPGL CO pause comments)
  std::string note;
};

// Which pen draws from a line on, as the job names it (G-code layer comments and pen
// change messages, HPGL SP).
struct PenLabel {
  size_t line = 0;
  std::string text;
};

struct Job {
  Dialect dialect = Dialect::GCode;
  std::vector<JobLine> lines;
  double est_total_s = 0;  // the timed plan's total (or distance / speed before timing)
  std::vector<PenLabel> pens;  // in line order
  // The pen in use at line `line` ("" when the job does not say). O(pens).
  std::string pen_at(size_t line) const;
};

// A pen-down move, or a touch (x0 == x1, y0 == y1): what a plotter's record holds.
struct Segment {
  double x0, y0, x1, y1;
  int pen = 1;  // HPGL pen number (1 for G-code)
  friend bool operator==(const Segment&, const Segment&) = default;
};

}  // namespace stipplot::io
