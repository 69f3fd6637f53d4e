#pragma once
// Raster preview of what the pens will draw on the paper (Cairo).
#include <string>

#include "geometry/drawing.hpp"
#include "image/image.hpp"

namespace stipplot {

struct PreviewOptions {
  double dpi = 150;
  // Ink darker than the paper multiplies with what is under it (as real ink does);
  // ink lighter than the paper (white gel pen on grey) covers it.
  bool ink_multiplies = true;
};

// Renders the whole page. O(primitives + output pixels).
Image render_preview(const Drawing& drawing, const PreviewOptions& opt = {});
// Renders and writes a PNG atomically.
void write_preview_png(const Drawing& drawing, const std::string& path, const PreviewOptions& opt = {});
// Writes any RGB image as PNG (through Cairo), atomically.
void write_png(const Image& image, const std::string& path);

}  // namespace stipplot
