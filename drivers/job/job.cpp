#include "drivers/job/job.hpp"

namespace stipplot::io {

const char* to_string(Dialect d) { return d == Dialect::Hpgl ? "hpgl" : "gcode"; }

}  // namespace stipplot::io
