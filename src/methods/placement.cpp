#include "methods/placement.hpp"

#include "util/error.hpp"

namespace stipplot {

void Placement::validate() const {
  require_nonnegative("--margin", margin_mm);
  require_range("--pen-width", pen_width_mm, 0.01, 50);
  require_nonnegative("--dot-size", dot_size.value);
}

}  // namespace stipplot
