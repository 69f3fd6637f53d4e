#pragma once
// Raster previews (Cairo). The pen-true render draws a Plan as the plotter will: every
// stroke at its pen's width in its pen's colour, a one-point stroke a disc of the pen's
// width, each pen's ink one layer (a pen crossing its own ink does not darken it)
// multiplying with what is under it, or covering it where the ink is lighter than the
// paper (a white gel pen on grey). It is the preview, the measure and what a plot looks
// like. The Drawing render shows primitives as they are (filled circles in their exact
// colours): for drawings in screen colours, which no pen draws.
#include <string>

#include "geometry/drawing.hpp"
#include "image/image.hpp"
#include "plan/plan.hpp"

namespace stipplot {

struct PreviewOptions {
  double dpi = 150;
  // Ink darker than the paper multiplies with what is under it (as real ink does);
  // ink lighter than the paper (white gel pen on grey) covers it. False: every layer
  // is opaque paint over what is under it.
  bool ink_multiplies = true;
};

// The pen-true render of a plan on its page. O(stroke points + output pixels x layers).
Image render_plan(const Plan& plan, const PreviewOptions& opt = {});

// Renders a Drawing's primitives (dots at max(diameter, pen width), circles filled in
// their own colour or outlined, polylines at the pen width). O(primitives + pixels).
Image render_preview(const Drawing& drawing, const PreviewOptions& opt = {});
// Renders and writes a PNG atomically.
void write_preview_png(const Drawing& drawing, const std::string& path, const PreviewOptions& opt = {});
// Writes any RGB image as PNG (through Cairo), atomically.
void write_png(const Image& image, const std::string& path);
// An uncompressed 24-bit TGA: read 10x faster than a PNG (and 5x faster than a BMP, which
// stb_image reads a byte at a time): the studio's reduced photo, read by every draft.
// Atomic like every output.
void write_tga(const Image& image, const std::string& path);

}  // namespace stipplot
