#pragma once
// The built-in pen palette for plotting pointillism (--plot-pens): fineliners.toml in
// this folder, compiled in and read by the one palette reader (methods/palette.hpp).
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::pointillism {

// The tip width of a pen whose palette entry gives none: pointillism's circles are
// filled at the pen width, and fineliners are 0.4 mm.
inline constexpr double kDefaultPenWidthMm = 0.4;

// 20 fineliner colours after the STABILO point 88 range. The hex values are eyeballed
// approximations of each ink on white paper, not measurements; for faithful colour,
// measure your pens and pass a TOML file.
std::vector<Pen> default_pens();

}  // namespace stipplot::pointillism
