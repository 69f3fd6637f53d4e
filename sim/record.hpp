#pragma once
// What a simulated plotter drew, as a Drawing (one layer per pen), rendered to PNG
// (Cairo, through the preview renderer) and SVG.
#include <string>
#include <vector>

#include "drivers/job/job.hpp"
#include "geometry/drawing.hpp"

namespace stipplot::sim {

// Segments in device units; `units_per_mm` 1 for G-code (mm), 40 for HPGL. Touches
// become dots of the pen width. `flip_y_mm` > 0 mirrors y (HPGL's origin is bottom-left).
Drawing record_to_drawing(const std::vector<io::Segment>& segs, const Page& page, double units_per_mm,
                          double pen_width_mm = 0.3, double flip_y_mm = 0);
// The page fitted around what was drawn (10 mm margin), so records of machines with
// negative coordinates or landscape pages render whole.
Drawing record_to_fitted_drawing(const std::vector<io::Segment>& segs, double units_per_mm, bool flip_y,
                                 double pen_width_mm = 0.3);
void write_drawing_png_svg(const Drawing& d, const std::string& png, const std::string& svg);
void write_record_png(const std::vector<io::Segment>& segs, const Page& page, double units_per_mm,
                      const std::string& path, double flip_y_mm = 0);
void write_record_svg(const std::vector<io::Segment>& segs, const Page& page, double units_per_mm,
                      const std::string& path, double flip_y_mm = 0);

}  // namespace stipplot::sim
