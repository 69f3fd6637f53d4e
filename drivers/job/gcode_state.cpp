#include "drivers/job/gcode_state.hpp"

#include <cmath>

namespace stipplot::io {

GcodeEffect GcodeState::apply(std::string_view line) {
  GcodeEffect e;
  bool axis[3] = {false, false, false};
  double value[3] = {0, 0, 0};
  int spindle = spindle_;
  double s = s_;
  bool have_s = false;
  for_each_gcode_word(line, [&](const GcodeWord& w) {
    switch (w.letter) {
      case 'G':
        if (!modes_.apply(w) && is_dwell(w)) e.dwell = true;
        break;
      case 'M': {
        const long m = std::lround(w.value);
        if (m == 3 || m == 4) spindle = static_cast<int>(m);
        else if (m == 5) spindle = 0;
        else if (m == 0 || m == 1) e.pause = true;
        else if (m == 2 || m == 30) e.end = true;
        break;
      }
      case 'S': s = w.value, have_s = true; break;
      case 'F': feed_written_ = w.value, feed_mm_min_ = w.value * modes_.scale; break;
      case 'P': e.dwell_p = w.value; break;
      case 'X': axis[0] = true, value[0] = w.value; break;
      case 'Y': axis[1] = true, value[1] = w.value; break;
      case 'Z': axis[2] = true, value[2] = w.value; break;
      default: break;
    }
  });
  // grbl (gcode.c): a new S while the spindle runs, or a new spindle state, is synced.
  e.spindle_change = spindle != spindle_ || (have_s && spindle != 0 && s != s_);
  spindle_ = spindle;
  s_ = s;
  if (e.end) spindle_ = 0;
  e.target = pos_;
  if (!e.dwell && (axis[0] || axis[1] || axis[2])) {
    for (int k = 0; k < 3; ++k)
      if (axis[k]) e.target[k] = modes_.absolute ? value[k] * modes_.scale : pos_[k] + value[k] * modes_.scale;
    e.move = true;
    e.rapid = modes_.motion == 0;
    e.feed_mm_min = feed_mm_min_;
    pos_ = e.target;
  }
  return e;
}

}  // namespace stipplot::io
