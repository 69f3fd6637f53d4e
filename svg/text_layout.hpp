#pragma once
// SVG text drawn with the single-stroke Hershey fonts of Debian's libhersheyfont
// (/usr/share/hershey-fonts), so labels and signatures plot as lines a pen can follow.
// The SVG reader collects the characters of <text>, <tspan>, <tref>, <textPath> and
// Inkscape's <flowRoot> with their styles and positions; this lays them out as SVG does:
//  - a character with an absolute x or y starts a new text chunk, dx/dy shift it, and each
//    chunk is moved by its text-anchor (start, middle, end);
//  - on a path, each glyph is centred on the point at its distance along it and turned
//    with the tangent (startOffset, anchor; glyphs beyond the end are not drawn);
//  - in a box (flowRoot), words are wrapped into lines of 1.25 font sizes.
// Font: font-family with "script"/"cursive" -> scripts, bold -> futuram (duplex),
// anything else -> futural (simplex); italic is the upright font slanted 15 degrees. A font
// size is 32 Hershey units (capitals are 21 high, as a Helvetica's 0.7 em). Characters the
// fonts lack (anything beyond ASCII) are left out and counted. Coordinates are user units,
// y down.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot::svgtext {

enum class Anchor { start, middle, end };

struct TextStyle {
  double size = 16;  // font size in user units (CSS's default 16px)
  std::string family;
  bool bold = false, italic = false;
  Anchor anchor = Anchor::start;
};

struct TextChar {
  char32_t code = ' ';
  TextStyle style;
  size_t paint = 0;  // the reader's own tag (which pen layer the glyph goes to)
  std::optional<double> x, y;
  double dx = 0, dy = 0;
  bool paragraph = false;  // in a box: starts a new paragraph
};

struct Glyph {
  size_t paint = 0;
  std::vector<std::vector<Vec2>> strokes;  // user units
};

struct TextResult {
  std::vector<Glyph> glyphs;
  size_t missing = 0;  // characters with no glyph in the fonts
};

// UTF-8 to code points; malformed bytes become U+FFFD (which has no glyph).
std::u32string decode_utf8(const std::string& s);

// `start` is the current text position when the first character has no x or y.
// O(characters + glyph points).
TextResult lay_out_text(const std::vector<TextChar>& chars, Vec2 start = {0, 0});
// Along a polyline in user units; start_offset in user units from its start.
// O(characters x log(path points) + glyph points).
TextResult lay_out_on_path(const std::vector<TextChar>& chars, const std::vector<Vec2>& path, double start_offset);
// Wrapped into `box` (user units), top line first; lines below the box are not drawn.
// O(characters + glyph points).
TextResult lay_out_in_box(const std::vector<TextChar>& chars, const Rect& box);

// Throws UserError naming the package when the fonts are not installed.
void require_fonts();

}  // namespace stipplot::svgtext
