#include "sim/record.hpp"

#include <algorithm>
#include <map>

#include "preview/preview.hpp"
#include "svg/svg_writer.hpp"

namespace stipplot::sim {

Drawing record_to_drawing(const std::vector<io::Segment>& segs, const Page& page, double upm, double pen_w,
                          double flip_y_mm) {
  Drawing d;
  d.page = page;
  std::map<int, size_t> layer_of;
  auto pt = [&](double x, double y) {
    Vec2 v{x / upm, y / upm};
    if (flip_y_mm > 0) v.y = flip_y_mm - v.y;
    return v;
  };
  for (const auto& s : segs) {
    auto it = layer_of.find(s.pen);
    if (it == layer_of.end()) {
      Layer l;
      l.pen.name = "pen " + std::to_string(s.pen);
      l.pen.width_mm = pen_w;
      d.layers.push_back(l);
      it = layer_of.emplace(s.pen, d.layers.size() - 1).first;
    }
    Layer& L = d.layers[it->second];
    if (s.x0 == s.x1 && s.y0 == s.y1) {
      L.dots.push_back({pt(s.x0, s.y0), pen_w});
      continue;
    }
    Vec2 a = pt(s.x0, s.y0), b = pt(s.x1, s.y1);
    if (!L.lines.empty() && L.lines.back().pts.back() == a) L.lines.back().pts.push_back(b);
    else L.lines.push_back({{a, b}});
  }
  return d;
}

Drawing record_to_fitted_drawing(const std::vector<io::Segment>& segs, double upm, bool flip_y, double pen_w) {
  double lx = 1e300, ly = 1e300, hx = -1e300, hy = -1e300;
  for (const auto& s : segs)
    for (double x : {s.x0, s.x1}) lx = std::min(lx, x / upm), hx = std::max(hx, x / upm);
  for (const auto& s : segs)
    for (double y : {s.y0, s.y1}) {
      double v = (flip_y ? -y : y) / upm;
      ly = std::min(ly, v), hy = std::max(hy, v);
    }
  if (segs.empty()) lx = ly = hx = hy = 0;
  const double m = 10;
  std::vector<io::Segment> moved = segs;
  for (auto& s : moved) {
    s.x0 = (s.x0 / upm - lx + m) * upm;
    s.x1 = (s.x1 / upm - lx + m) * upm;
    s.y0 = ((flip_y ? -s.y0 : s.y0) / upm - ly + m) * upm;
    s.y1 = ((flip_y ? -s.y1 : s.y1) / upm - ly + m) * upm;
  }
  Page page;
  page.width_mm = hx - lx + 2 * m;
  page.height_mm = hy - ly + 2 * m;
  return record_to_drawing(moved, page, upm, pen_w, 0);
}

void write_drawing_png_svg(const Drawing& d, const std::string& png, const std::string& svg) {
  if (!png.empty()) write_preview_png(d, png);
  if (!svg.empty()) write_svg(d, svg);
}

void write_record_png(const std::vector<io::Segment>& segs, const Page& page, double upm, const std::string& path,
                      double flip_y_mm) {
  write_preview_png(record_to_drawing(segs, page, upm, 0.3, flip_y_mm), path);
}

void write_record_svg(const std::vector<io::Segment>& segs, const Page& page, double upm, const std::string& path,
                      double flip_y_mm) {
  write_svg(record_to_drawing(segs, page, upm, 0.3, flip_y_mm), path);
}

}  // namespace stipplot::sim
