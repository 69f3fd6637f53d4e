#pragma once
// SVG output of a Drawing: millimetre units with a matching viewBox, one Inkscape
// layer per pen, and the paper as a background rect in a layer marked non-plotting
// (its label starts with '%', which the AxiDraw tools skip; class="non-plotting").
#include <string>

#include "geometry/drawing.hpp"

namespace stipplot {

struct SvgOptions {
  bool paper_background = true;
  int decimals = 3;  // micrometre resolution
};

// Writes atomically: the file appears complete or not at all. Streams, so memory
// stays O(1) beyond the drawing. O(number of primitives).
void write_svg(const Drawing& drawing, const std::string& path, const SvgOptions& opt = {});
std::string svg_string(const Drawing& drawing, const SvgOptions& opt = {});

// Formats v with at most `decimals` digits after the point, trailing zeros trimmed.
std::string format_number(double v, int decimals);
// The same, appended to out (no string of its own: the writers print millions).
void append_number(std::string& out, double v, int decimals);

}  // namespace stipplot
