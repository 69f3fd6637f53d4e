#pragma once
// A set of real pens the user owns, read from a TOML file. Shared by the methods that
// draw with user pens (sketch, pointillism). Format:
//
//   name = "Stabilo point 88, 8 colours"   # optional
//   [[pen]]
//   name = "red"            # unique, non-empty
//   color = "#d7261e"       # #rrggbb (or #rgb / an SVG colour name)
//   width = 0.4             # mm, optional (default 0.3), 0.01 .. 50
//
// Unknown keys are rejected so a typo ("colour", "widht") is not silently ignored.
#include <string>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot {

struct Palette {
  std::string name;
  std::vector<Pen> pens;
};

// Parses TOML text; `source` names the file in error messages. Throws UserError with
// one line naming the file, the pen and the problem: TOML syntax, no pens, missing or
// duplicate names, bad colours, bad widths, unknown keys. O(text length + pens^2).
Palette parse_palette(const std::string& toml_text, const std::string& source = "palette");

// Reads and parses a palette file; throws UserError if it cannot be read.
Palette load_palette(const std::string& path);

}  // namespace stipplot
