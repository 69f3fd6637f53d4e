#include "methods/placement.hpp"

#include "util/error.hpp"

namespace stipplot {

void Placement::validate() const {
  require_range("--margin (mm)", margin_mm, 0, 1e6);
  require_range("--pen-width (mm)", pen_width_mm, 0.01, 50);
  // A dot wider than any pen tip draws as a filled circle; past 100 mm it is no dot.
  if (dot_size.in_px)
    require_range("--dot-size (input px)", dot_size.value, 0, 10000);
  else
    require_range("--dot-size (mm)", dot_size.value, 0, 100);
}

}  // namespace stipplot
