#pragma once
// Pen palettes for plotting pointillism: a set of real pens (name, ink colour, tip
// width) and the nearest pen to a colour in CIEDE2000.
//
// TOML format, one table per pen:
//   [[pen]]
//   name = "red"
//   color = "#e42a26"
//   width = 0.4        # mm, optional (default 0.4)
#include <string>
#include <unordered_map>
#include <vector>

#include "geometry/drawing.hpp"
#include "methods/pointillism/lab.hpp"

namespace stipplot::pointillism {

// A built-in palette of common fineliner colours (after the STABILO point 88 range).
// The hex values are eyeballed approximations of each ink on white paper, not
// measurements; for faithful colour, measure your pens and pass a TOML file.
std::vector<Pen> default_pens();

// Parses a TOML palette. `source` names the file in error messages. Throws UserError
// (one line, naming the file, line and field) for malformed TOML, a missing or
// malformed name/color, a width outside (0, 50] mm, unknown keys, or no pens at all.
std::vector<Pen> parse_pens(const std::string& toml_text, const std::string& source);
std::vector<Pen> load_pens(const std::string& path);

// Nearest pen to a colour by CIEDE2000, memoised per 8-bit colour (photos repeat
// colours a lot). O(pens) per new colour, O(1) for a repeated one.
class PenMatcher {
 public:
  explicit PenMatcher(std::vector<Pen> pens);  // throws UserError when empty
  size_t nearest(Color c);
  const std::vector<Pen>& pens() const { return pens_; }

 private:
  std::vector<Pen> pens_;
  std::vector<lab::Lab> pen_lab_;
  std::unordered_map<uint32_t, uint32_t> cache_;
};

}  // namespace stipplot::pointillism
