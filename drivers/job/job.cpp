#include "drivers/job/job.hpp"

namespace stipplot::io {

const char* to_string(Dialect d) {
  switch (d) {
    case Dialect::GCode: return "gcode";
    case Dialect::Hpgl: return "hpgl";
    case Dialect::Ebb: return "ebb";
  }
  return "?";
}

std::string Job::pen_at(size_t line) const {
  std::string out;
  for (const PenLabel& p : pens) {
    if (p.line > line) break;
    out = p.text;
  }
  return out;
}

}  // namespace stipplot::io
