#include "methods/pointillism/pens.hpp"

#include "methods/palette.hpp"

namespace stipplot::pointillism {

// fineliners.toml's text, generated into the build tree by this folder's CMakeLists.
extern const char* const kFinelinersToml;

std::vector<Pen> default_pens() {
  static const std::vector<Pen> pens = parse_palette(kFinelinersToml, "built-in fineliners.toml", kDefaultPenWidthMm).pens;
  return pens;
}

}  // namespace stipplot::pointillism
