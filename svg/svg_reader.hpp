#pragma once
// Reads an SVG that someone drew elsewhere into a Drawing, so it can be planned and
// plotted like a method's output.
//  - Shapes: path (M L H V C S Q T A Z, absolute and relative), line, polyline, polygon,
//    rect (with rx/ry), circle, ellipse. Curves and arcs are flattened to polylines within
//    `tolerance_mm` measured on the page (after all transforms).
//  - Nested transforms: matrix, translate, scale, rotate(a [cx cy]), skewX, skewY.
//  - Units: the root's width/height (mm, cm, in, pt, pc, px at 96/in) with its viewBox
//    (preserveAspectRatio none or the default xMidYMid meet) give the page in mm.
//  - Layers: an Inkscape layer (g with inkscape:groupmode="layer", outermost one wins)
//    becomes a pen layer named by its label; a leading "N " (up to 4 digits) is the pen
//    number, as the AxiDraw tools read it, and is dropped from the name;
//    shapes outside any layer are grouped into pen layers by stroke colour (fill if no
//    stroke). display:none, visibility:hidden and layers labelled "%..." are skipped.
//  - A filled, unstroked circle no wider than the stroke width in effect becomes a Dot
//    (one pen touch, as stipplot's own SVG writes its dots); other circles stay circles
//    when the transform keeps them round.
// Malformed input (XML errors, bad path data, bad numbers or transforms) throws UserError
// naming the file, the XML line and the element; so do points beyond kMaxCoordinateMm of
// the page's origin, transforms that are not finite or stretch beyond 1e9, and drawings
// over the caps below.
#include <string>

#include "geometry/drawing.hpp"

namespace stipplot {

struct SvgReadOptions {
  double tolerance_mm = 0.05;          // max distance of a flattened curve from the true one
  double default_pen_width_mm = 0.3;   // when the SVG gives no stroke width
  // Work caps, checked before the work: elements drawn through <use> (each copy counts,
  // so nested <use> cannot multiply without end) and points made (flattened curves
  // included; 16 bytes each).
  size_t max_use_copies = 1'000'000;
  size_t max_points = 10'000'000;
  // Read in two streaming passes, holding only open groups and referenced elements
  // (false: through tinyxml2's tree of the whole file; the tests compare the two).
  bool stream = true;
  // Streaming, expat tokenises on a thread of its own beside the drawing of the elements
  // when two threads are allowed (util/threads.hpp) and the source holds at least this
  // many bytes; 0: always, on any thread count (the tests). The same drawing either way.
  size_t tokenize_apart_from_bytes = size_t{4} << 20;
};

// O(elements + output points); the flattening adds points in proportion to
// sqrt(curve size / tolerance) per curve. Memory: the drawing plus the elements an href
// names and the groups open at a time, not the document's tree (see `stream`).
// What reading left out that a user should hear of.
struct SvgReadReport {
  size_t missing_glyphs = 0;  // text characters the Hershey fonts have no glyph for
  bool streamed = false;      // read in streaming passes, not through the whole tree
};

Drawing read_svg(const std::string& path, const SvgReadOptions& opt = {}, SvgReadReport* report = nullptr);
// `name` is used in error messages.
Drawing parse_svg(const std::string& text, const std::string& name, const SvgReadOptions& opt = {},
                  SvgReadReport* report = nullptr);

}  // namespace stipplot
