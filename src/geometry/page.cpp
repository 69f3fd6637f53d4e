#include "geometry/page.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot {

PageSpec parse_page(const std::string& text) {
  std::string t = text;
  std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return std::tolower(c); });
  struct Named {
    const char* name;
    double w, h;
  };
  static const Named named[] = {{"a5", 148, 210},   {"a4", 210, 297},     {"a3", 297, 420},
                                {"a2", 420, 594},   {"letter", 215.9, 279.4}, {"legal", 215.9, 355.6},
                                {"tabloid", 279.4, 431.8}};
  for (const auto& n : named)
    if (t == n.name) return {n.w, n.h};
  // WxH with one unit for both sides (the shared length grammar).
  if (const size_t x = t.find('x'); x != std::string::npos) {
    double w = 0, h = 0;
    std::string left_unit, unit;
    if (!split_number_unit(std::string_view(t).substr(0, x), w, left_unit) || !left_unit.empty() ||
        !split_number_unit(std::string_view(t).substr(x + 1), h, unit) || mm_per_unit(unit) == 0)
      throw UserError("--page: cannot read '" + text + "' as WxH with a unit of mm, cm, in, pt or px");
    w *= mm_per_unit(unit);
    h *= mm_per_unit(unit);
    if (!(w > 0) || !(h > 0) || w > 100000 || h > 100000)
      throw UserError("--page: size must be positive and at most 100 m, got '" + text + "'");
    return {w, h};
  }
  throw UserError("--page: unknown page '" + text + "' (use A5, A4, A3, A2, letter, legal, tabloid or WxHmm)");
}

PageTransform::PageTransform(int image_w, int image_h, PageSpec page, double margin_mm, bool landscape) {
  if (image_w <= 0 || image_h <= 0) throw UserError("image has no pixels");
  require_nonnegative("--margin", margin_mm);
  double pw = page.width_mm, ph = page.height_mm;
  // Named pages are portrait, custom sizes as given; --landscape puts the long side across.
  if (landscape && pw < ph) std::swap(pw, ph);
  if (2 * margin_mm >= std::min(pw, ph))
    throw UserError("--margin " + std::to_string(margin_mm) + " mm leaves no room on the page");
  pw_ = pw;
  ph_ = ph;
  double aw = pw - 2 * margin_mm, ah = ph - 2 * margin_mm;
  scale_ = std::min(aw / image_w, ah / image_h);
  ox_ = (pw - scale_ * image_w) / 2;
  oy_ = (ph - scale_ * image_h) / 2;
}

}  // namespace stipplot
