#include "layout/layout.hpp"

#include <cmath>
#include <sstream>

#include "util/error.hpp"

namespace stipplot::layout {

Align parse_align(const std::string& text) {
  static const std::pair<const char*, Align> names[] = {
      {"top-left", Align::top_left},       {"top", Align::top},         {"top-right", Align::top_right},
      {"left", Align::left},               {"center", Align::center},   {"centre", Align::center},
      {"right", Align::right},             {"bottom-left", Align::bottom_left}, {"bottom", Align::bottom},
      {"bottom-right", Align::bottom_right}};
  for (const auto& [name, a] : names)
    if (text == name) return a;
  throw UserError("--align must be center, top, bottom, left, right, top-left, top-right, bottom-left or "
                  "bottom-right (got '" + text + "')");
}

void LayoutOptions::validate() const {
  require_range("sheet width", sheet.width_mm, 1, 100000);
  require_range("sheet height", sheet.height_mm, 1, 100000);
  require_range("--margin", margin_mm, 0, 10000);
  require_range("--scale", scale, 1e-6, 1e6);
  if (fit && scale != 1) throw UserError("--fit and --scale exclude each other: fit chooses the scale");
  if (rotate_degrees) require_range("--rotate", *rotate_degrees, -36000, 36000);
  if (crop && crop->empty()) throw UserError("--crop: the rectangle must have a positive width and height");
}

Rect target_area(const LayoutOptions& opt) {
  const double m = opt.margin_mm;
  Rect a{m, m, opt.sheet.width_mm - m, opt.sheet.height_mm - m};
  if (a.empty()) {
    std::ostringstream msg;
    msg << "--margin " << m << " mm leaves no room on the " << opt.sheet.width_mm << " x " << opt.sheet.height_mm
        << " mm sheet";
    throw UserError(msg.str());
  }
  if (opt.reach) {
    a = a.intersect(*opt.reach);
    if (a.empty()) throw UserError("the device reaches no part of the sheet inside the margins");
  }
  return a;
}

void transform_drawing(Drawing& d, const Affine& t) {
  const double s = std::sqrt(std::fabs(t.det()));
  for (auto& l : d.layers) {
    for (auto& dot : l.dots) {
      dot.c = t.apply(dot.c);
      dot.diameter *= s;
    }
    for (auto& c : l.circles) {
      c.c = t.apply(c.c);
      c.r *= s;
    }
    for (auto& pl : l.lines)
      for (auto& p : pl.pts) p = t.apply(p);
    for (auto& a : l.areas)
      for (auto& ring : a.rings)
        for (auto& p : ring.pts) p = t.apply(p);
  }
}

namespace {

bool landscape(double w, double h) { return w > h; }

// The rotation about the page centre, moved so the rotated page's bounding box starts at
// (0, 0); `page` becomes that box.
Affine rotate_page(double deg, double& w, double& h) {
  const Affine r = Affine::rotate_degrees(deg);
  const Vec2 corners[4] = {r.apply({0, 0}), r.apply({w, 0}), r.apply({0, h}), r.apply({w, h})};
  Vec2 lo = corners[0], hi = corners[0];
  for (const Vec2& c : corners) {
    lo = {std::min(lo.x, c.x), std::min(lo.y, c.y)};
    hi = {std::max(hi.x, c.x), std::max(hi.y, c.y)};
  }
  w = hi.x - lo.x;
  h = hi.y - lo.y;
  return Affine::translate(-lo.x, -lo.y) * r;
}

// Where a box of size (w, h) starts so it sits at `align` within `area`.
Vec2 aligned_origin(Align align, const Rect& area, double w, double h) {
  const int col = static_cast<int>(align) % 3, row = static_cast<int>(align) / 3;
  const double x = col == 0 ? area.x0 : col == 1 ? area.x0 + (area.width() - w) / 2 : area.x1 - w;
  const double y = row == 0 ? area.y0 : row == 1 ? area.y0 + (area.height() - h) / 2 : area.y1 - h;
  return {x, y};
}

// Fit or align: scale (fit only) and move the ink's bounding box into the target area.
Affine place_ink(const Drawing& d, const LayoutOptions& opt, LayoutReport& rep) {
  Vec2 lo, hi;
  if (!d.bounds(lo, hi)) return {};
  rep.area = target_area(opt);
  const double bw = hi.x - lo.x, bh = hi.y - lo.y;
  double k = 1;
  if (opt.fit) {
    const double kx = bw > 0 ? rep.area.width() / bw : INFINITY, ky = bh > 0 ? rep.area.height() / bh : INFINITY;
    k = std::min(kx, ky);
    if (!std::isfinite(k)) k = 1;  // a single point: nothing to scale
  }
  const Vec2 at = aligned_origin(opt.align.value_or(Align::center), rep.area, bw * k, bh * k);
  rep.scale *= k;
  return Affine::translate(at.x, at.y) * Affine::scale(k) * Affine::translate(-lo.x, -lo.y);
}

}  // namespace

Drawing lay_out(Drawing d, const LayoutOptions& opt, LayoutReport* report) {
  opt.validate();
  LayoutReport rep;
  if (opt.crop) rep.cropped = clip_to_rect(d, *opt.crop);
  double w = d.page.width_mm, h = d.page.height_mm;
  // What is turned to the sheet's orientation: the page, or with fit the ink it fits.
  double ow = w, oh = h;
  Vec2 lo, hi;
  if (opt.fit && d.bounds(lo, hi)) ow = hi.x - lo.x, oh = hi.y - lo.y;
  double deg = 0;
  if (opt.rotate_degrees) {
    deg = *opt.rotate_degrees;
  } else if (opt.auto_rotate && ow != oh && opt.sheet.width_mm != opt.sheet.height_mm &&
             landscape(ow, oh) != landscape(opt.sheet.width_mm, opt.sheet.height_mm)) {
    deg = -90;
    rep.auto_rotated = true;
  }
  Affine t = rotate_page(deg, w, h);
  rep.rotated_degrees = deg;
  rep.scale = opt.scale;
  t = Affine::scale(opt.scale) * t;
  transform_drawing(d, t);
  if (opt.fit || opt.align) {
    const Affine place = place_ink(d, opt, rep);
    transform_drawing(d, place);
    t = place * t;
  }
  d.page.width_mm = opt.sheet.width_mm;
  d.page.height_mm = opt.sheet.height_mm;
  rep.clipped = clip_to_rect(d, {0, 0, opt.sheet.width_mm, opt.sheet.height_mm});
  rep.transform = t;
  if (report) *report = rep;
  return d;
}

std::string describe(const LayoutReport& r) {
  std::ostringstream s;
  s.precision(3);
  auto sep = [&] {
    if (s.tellp() > 0) s << ", ";
  };
  if (r.auto_rotated) s << "rotated 90° to the sheet's orientation";
  else if (r.rotated_degrees != 0) s << "rotated " << r.rotated_degrees << "°";
  if (std::fabs(r.scale - 1) > 5e-4) {
    sep();
    s << "scaled " << r.scale << "×";
  }
  if (r.cropped.total() > 0) {
    sep();
    s << r.cropped.total() << " shapes cropped";
  }
  if (r.clipped.total() > 0) {
    sep();
    s << r.clipped.total() << " shapes clipped at the sheet's edge (" << r.clipped.cut << " cut, " << r.clipped.dropped
      << " dropped)";
  }
  return s.str();
}

}  // namespace stipplot::layout
