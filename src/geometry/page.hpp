#pragma once
// Page sizes and the fit-with-margin transform from image pixels to page millimetres.
#include <string>

#include "geometry/drawing.hpp"

namespace stipplot {

struct PageSpec {
  double width_mm = 210, height_mm = 297;
};

// "A4", "A3", "A5", "letter", "legal", "tabloid", or "WxH" with one unit of util/units.hpp
// for both sides ("300x200mm", "30x20cm", "11x8.5in"; bare numbers are mm).
// Throws UserError naming the text when it is none of these or not positive.
PageSpec parse_page(const std::string& text);

// Maps pixel coordinates (x right, y down; pixel (i,j) covers [i,i+1]x[j,j+1]) onto
// the page: uniform scale so the image fits inside the margins, centred.
class PageTransform {
 public:
  PageTransform() = default;
  // landscape: orient the page so its long side is horizontal (else as specified).
  PageTransform(int image_w, int image_h, PageSpec page, double margin_mm, bool landscape);
  Vec2 map(double px, double py) const { return {ox_ + px * scale_, oy_ + py * scale_}; }
  Vec2 unmap(Vec2 mm) const { return {(mm.x - ox_) / scale_, (mm.y - oy_) / scale_}; }
  double mm_per_px() const { return scale_; }
  double page_w() const { return pw_; }
  double page_h() const { return ph_; }
  double origin_x() const { return ox_; }
  double origin_y() const { return oy_; }

 private:
  double scale_ = 1, ox_ = 0, oy_ = 0, pw_ = 210, ph_ = 297;
};

}  // namespace stipplot
