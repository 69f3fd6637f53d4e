#include "sim/record.hpp"

#include <map>

#include "preview/preview.hpp"
#include "svg_writer.hpp"

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

void write_record_png(const std::vector<io::Segment>& segs, const Page& page, double upm, const std::string& path,
                      double flip_y_mm) {
  write_preview_png(record_to_drawing(segs, page, upm, 0.3, flip_y_mm), path);
}

void write_record_svg(const std::vector<io::Segment>& segs, const Page& page, double upm, const std::string& path,
                      double flip_y_mm) {
  write_svg(record_to_drawing(segs, page, upm, 0.3, flip_y_mm), path);
}

}  // namespace stipplot::sim
