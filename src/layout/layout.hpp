#pragma once
// Laying a drawing out on a sheet, in the manner of vpype's layout and the AxiDraw
// tools: a Drawing -> Drawing stage between a drawing (a method's output or an SVG as
// read) and the planner. In order:
//   1. crop   — cut the drawing to a rectangle of its own page (what to keep);
//   2. rotate — by rotate_degrees (clockwise) about the page centre; or, when none is
//               given, by 90 degrees (counter-clockwise, as vpype's pagerotate) if the page's
//               orientation (with fit: the ink's) differs from the sheet's (a portrait
//               drawing on a landscape plotter), unless auto_rotate is off;
//   3. scale  — by a factor, or fit: the drawing's ink (its bounding box) scaled, keeping
//               its aspect, to fill the area of the sheet inside the margins and the
//               device's reach;
//   4. place  — fit or align put the ink at the alignment point of that area (centred by
//               default with fit); otherwise the page's top-left corner is the sheet's;
//   5. clip   — everything off the sheet is cut off (layout/clip.hpp) and counted.
// The drawing's page becomes the sheet. Whether the result lies within the device's
// travel is the writers' check (drivers/device/machine.hpp), which refuses it whole.
#include <optional>
#include <string>

#include "geometry/affine.hpp"
#include "geometry/drawing.hpp"
#include "layout/clip.hpp"

namespace stipplot::layout {

// Where fit or align put the ink within the target area.
enum class Align { top_left, top, top_right, left, center, right, bottom_left, bottom, bottom_right };
// "center", "top-left", "top", "bottom-right", ... (also "centre"); UserError naming --align.
Align parse_align(const std::string& text);

struct LayoutOptions {
  Page sheet;                    // the paper the drawing is laid on (its size and orientation)
  double margin_mm = 0;          // fit and align keep this far inside the sheet's edges
  std::optional<Rect> reach;     // the part of the sheet the device reaches, if known
  std::optional<Rect> crop;      // in the drawing's own page millimetres
  std::optional<double> rotate_degrees;
  bool auto_rotate = true;
  bool fit = false;
  double scale = 1;              // excludes fit
  std::optional<Align> align;    // default with fit: center
  void validate() const;         // UserError naming the option
};

struct LayoutReport {
  Affine transform;              // the drawing's page -> the sheet
  double rotated_degrees = 0;    // as applied (auto or asked)
  bool auto_rotated = false;     // turned to the sheet's orientation by itself
  double scale = 1;              // the size change (fit's or asked)
  ClipCounts cropped, clipped;   // by --crop, and at the sheet's edge
  Rect area;                     // where fit / align placed the ink
};

// The area fit and align use: the sheet less its margins, within the reach. Throws
// UserError when nothing is left.
Rect target_area(const LayoutOptions& opt);

// O(points of the drawing).
Drawing lay_out(Drawing d, const LayoutOptions& opt, LayoutReport* report = nullptr);

// Every point, circle and dot of the drawing through `t`, which must be a similarity
// (rotation, uniform scale, reflection, translation) so circles stay circles. O(points).
void transform_drawing(Drawing& d, const Affine& t);

// "rotated 90° to the sheet's orientation, 3 strokes clipped at the sheet's edge": what the
// commands' result lines say about a layout; empty when it changed nothing worth saying.
std::string describe(const LayoutReport& r);

}  // namespace stipplot::layout
