#pragma once
// grbl's modal state as a job's lines change it, one line at a time: where each line
// moves the machine (mm, with G20/G21 and G90/G91), at what feed, and which lines make
// grbl wait for its planner to empty first (a spindle/pen change, a dwell, a pause, the
// program end). The job timer, the executed-line tracker and resume planning share it.
#include <array>
#include <string>

#include "drivers/job/gcode_reader.hpp"

namespace stipplot::io {

struct GcodeEffect {
  bool move = false, rapid = false;
  std::array<double, 3> target{};  // where the line leaves the machine (mm)
  double feed_mm_min = 0;          // for G1
  bool spindle_change = false;     // M3/M4/M5 or a new S while on: grbl syncs first
  bool dwell = false;
  double dwell_p = 0;              // G4 P, seconds as written
  bool pause = false;              // M0/M1
  bool end = false;                // M2/M30
  bool syncs() const { return spindle_change || dwell || pause || end; }
};

class GcodeState {
 public:
  // Applies one job line (comments already stripped). O(line length).
  GcodeEffect apply(std::string_view line);
  // The machine is at `mm` (it starts at zero).
  void set_position(const std::array<double, 3>& mm) { pos_ = mm; }

  const GcodeModes& modes() const { return modes_; }
  double feed_mm_min() const { return feed_mm_min_; }
  double feed_as_written() const { return feed_written_; }  // in the job's own units
  bool spindle_on() const { return spindle_ != 0; }
  int spindle_m() const { return spindle_ ? spindle_ : 5; }   // 3, 4 or 5
  double spindle_s() const { return s_; }
  const std::array<double, 3>& position() const { return pos_; }

 private:
  GcodeModes modes_;
  double feed_mm_min_ = 0, feed_written_ = 0, s_ = 0;
  int spindle_ = 0;  // 0 off, 3 CW, 4 CCW
  std::array<double, 3> pos_{};
};

}  // namespace stipplot::io
