#pragma once
// How a method's pixel-space result is laid on paper: page, margin, pen width and
// drawn dot size. Shared by every method so the CLI options mean the same everywhere.
#include <string>

#include "geometry/page.hpp"

namespace stipplot {

// A length given in input-image pixels ("1.5px") or in millimetres ("0.4mm", "0.4").
struct Length {
  double value = 0;
  bool in_px = false;
  double to_mm(double mm_per_px) const { return in_px ? value * mm_per_px : value; }
  // Throws UserError naming `option` for a malformed, negative or non-finite length.
  static Length parse(const std::string& text, const char* option);
};

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
