#include "methods/placement.hpp"

#include <cmath>
#include <cstdlib>

#include "util/error.hpp"

namespace stipplot {

Length Length::parse(const std::string& text, const char* option) {
  Length l;
  std::string t = text;
  if (t.size() > 2 && t.compare(t.size() - 2, 2, "px") == 0) {
    l.in_px = true;
    t.resize(t.size() - 2);
  } else if (t.size() > 2 && t.compare(t.size() - 2, 2, "mm") == 0) {
    t.resize(t.size() - 2);
  }
  char* end = nullptr;
  l.value = std::strtod(t.c_str(), &end);
  if (t.empty() || end == t.c_str() || *end != '\0' || !std::isfinite(l.value) || l.value < 0)
    throw UserError(std::string(option) + ": expected a length >= 0 such as 0.4, 0.4mm or 1.5px, got '" + text + "'");
  return l;
}

void Placement::validate() const {
  require_nonnegative("--margin", margin_mm);
  require_range("--pen-width", pen_width_mm, 0.01, 50);
  require_nonnegative("--dot-size", dot_size.value);
}

}  // namespace stipplot
