#pragma once
// How a method's pixel-space result is laid on paper: page, margin, pen width and
// drawn dot size. Shared by every method so the CLI options mean the same everywhere.
#include <string>

#include "geometry/page.hpp"
#include "util/units.hpp"

namespace stipplot {

struct Placement {
  PageSpec page{210, 297};
  double margin_mm = 10;
  bool landscape = false;
  double pen_width_mm = 0.3;
  Length dot_size{0, false};  // 0 = the pen width
  PageTransform transform(int image_w, int image_h) const {
    return PageTransform(image_w, image_h, page, margin_mm, landscape);
  }
  double dot_diameter_mm(double mm_per_px) const {
    double d = dot_size.to_mm(mm_per_px);
    return d > 0 ? d : pen_width_mm;
  }
  void validate() const;
};

}  // namespace stipplot
