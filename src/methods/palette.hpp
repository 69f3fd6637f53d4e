#pragma once
// A set of real pens the user owns, read from a TOML file, and the nearest of them to a
// colour. One reader for every method that draws with user pens (sketch, pointillism)
// and for the built-in pointillism fineliners. Format:
//
//   name = "Stabilo point 88, 8 colours"   # optional
//   [[pen]]
//   name = "red"            # unique, non-empty
//   color = "#d7261e"       # #rrggbb (or #rgb / an SVG colour name)
//   width = 0.4             # mm, optional (the method's default), 0.01 .. 50
//
// Unknown keys are rejected so a typo ("colour", "widht") is not silently ignored.
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "eval/lab.hpp"
#include "geometry/drawing.hpp"

namespace stipplot {

struct Palette {
  std::string name;
  std::vector<Pen> pens;
};

// Parses TOML text; `source` names the file in error messages; pens without a width get
// `default_width_mm`. Throws UserError with one line naming the file, the pen and the
// problem: TOML syntax (with its line), no pens, missing or duplicate names, bad colours,
// bad widths, unknown keys. O(text length + pens log pens).
Palette parse_palette(const std::string& toml_text, const std::string& source = "palette",
                      double default_width_mm = 0.3);

// Reads and parses a palette file; throws UserError if it cannot be read.
Palette load_palette(const std::string& path, double default_width_mm = 0.3);

// Nearest pen to a colour by CIEDE2000, memoised per 8-bit colour (photos repeat
// colours a lot). O(pens) per new colour, O(1) for a repeated one.
class PenMatcher {
 public:
  explicit PenMatcher(std::vector<Pen> pens);  // throws UserError when empty
  size_t nearest(Color c);
  const std::vector<Pen>& pens() const { return pens_; }

 private:
  std::vector<Pen> pens_;
  std::vector<Lab> pen_lab_;
  std::unordered_map<uint32_t, uint32_t> cache_;
};

}  // namespace stipplot
