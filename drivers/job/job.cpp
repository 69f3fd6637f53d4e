#include "drivers/job/job.hpp"

namespace stipplot::io {

const char* to_string(Dialect d) { return d == Dialect::Hpgl ? "hpgl" : "gcode"; }

std::string Job::pen_at(size_t line) const {
  std::string out;
  for (const PenLabel& p : pens) {
    if (p.line > line) break;
    out = p.text;
  }
  return out;
}

}  // namespace stipplot::io
