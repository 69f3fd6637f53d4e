#pragma once
// The frame every SVG writer here puts around its drawing: the XML declaration, <svg> in
// millimetres with a matching viewBox, the title, the paper as a background rect on a
// layer labelled '%' (which plotting tools skip), and one Inkscape layer per pen.
#include <tinyxml2.h>

#include <string>
#include <vector>

#include "geometry/drawing.hpp"

namespace stipplot {

struct SvgFrame {
  Page page;
  std::string title;
  bool paper_background = true;
  // The paper layer also locked in Inkscape (sodipodi:insensitive, which declares the
  // sodipodi namespace) and classed "non-plotting".
  bool lock_paper = false;
  int decimals = 3;
};

// Writes everything up to the first pen layer and leaves <svg> open (close it with
// CloseElement).
void open_svg_document(tinyxml2::XMLPrinter& p, const SvgFrame& frame);

// Opens pen layer `index` (1-based; label "index name") with the pen's colour and width
// as stroke defaults; close it with CloseElement.
void open_pen_layer(tinyxml2::XMLPrinter& p, int index, const Pen& pen, int decimals);

// A line of more points than this is written as consecutive elements, each starting at
// the last one's end (stipplot export joins them again: the ends meet). rsvg-convert 2.54
// (libxml2 2.9) stops with "Premature end of data" about 10 MB into a file whose elements
// run to 10,000 points (140 kB) each, and reads the same file in elements of 1,000.
inline constexpr size_t kMaxElementPoints = 1'000;

// A line as <polyline points> or <path d="M ... L ...">, split as above; `scratch` is
// reused between calls. O(points).
enum class LineElement { polyline, path };
void push_line(tinyxml2::XMLPrinter& p, const std::vector<Vec2>& pts, LineElement as, int decimals, std::string& scratch);
// Lines one after another, each as push_line writes it; their numbers are formatted on
// every thread (util/threads.hpp) in batches of elements while this thread writes the
// batch before: the same text on any thread count. Empty lines are skipped. O(points).
void push_lines(tinyxml2::XMLPrinter& p, const std::vector<const std::vector<Vec2>*>& lines, LineElement as, int decimals);

// A filled disc without outline (<circle ... fill stroke="none"/>): a dot of ink.
void push_filled_circle(tinyxml2::XMLPrinter& p, Vec2 c, double r, const std::string& fill, int decimals);

}  // namespace stipplot
