#include "util/error.hpp"

#include <cmath>
#include <sstream>

namespace stipplot {

void require_range(const char* name, double v, double lo, double hi) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    std::ostringstream os;
    os << name << " must be a number in [" << lo << ", " << hi << "], got " << v;
    throw UserError(os.str());
  }
}

void require_nonnegative(const char* name, double v) {
  if (!std::isfinite(v) || v < 0) {
    std::ostringstream os;
    os << name << " must be a finite number >= 0, got " << v;
    throw UserError(os.str());
  }
}

void require_positive(const char* name, double v) {
  if (!std::isfinite(v) || v <= 0) {
    std::ostringstream os;
    os << name << " must be a finite number > 0, got " << v;
    throw UserError(os.str());
  }
}

}  // namespace stipplot
