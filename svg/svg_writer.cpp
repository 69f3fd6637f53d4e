#include "svg/svg_writer.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "svg/svg_document.hpp"
#include "svg/xml_output.hpp"
#include "util/atomic_file.hpp"
#include "util/decimal_text.hpp"
#include "util/error.hpp"

namespace stipplot {

void append_number(std::string& out, double v, int decimals) {
  if (!std::isfinite(v)) throw std::logic_error("non-finite coordinate in drawing");
  append_decimal(out, v, decimals);
}

std::string format_number(double v, int decimals) {
  std::string s;
  append_number(s, v, decimals);
  return s;
}

namespace {

// A filled region as one path of closed subpaths with its fill rule, no outline.
void push_area(tinyxml2::XMLPrinter& p, const Area& a, int decimals) {
  std::string d;
  for (const auto& ring : a.rings) {
    if (ring.pts.size() < 3) continue;
    for (size_t i = 0; i + 1 < ring.pts.size(); ++i) {
      d += i ? " L" : (d.empty() ? "M" : " M");
      append_number(d, ring.pts[i].x, decimals);
      d += ',';
      append_number(d, ring.pts[i].y, decimals);
    }
    d += " Z";
  }
  if (d.empty()) return;
  p.OpenElement("path");
  p.PushAttribute("d", d.c_str());
  p.PushAttribute("fill", a.fill.hex().c_str());
  p.PushAttribute("fill-rule", a.rule == FillRule::evenodd ? "evenodd" : "nonzero");
  p.PushAttribute("stroke", "none");
  p.CloseElement(true);
}

void write(const Drawing& d, tinyxml2::XMLPrinter& p, const SvgOptions& opt) {
  auto num = [&](double v) { return format_number(v, opt.decimals); };
  SvgFrame frame;
  frame.page = d.page;
  frame.title = "stipplot drawing";
  frame.paper_background = opt.paper_background;
  frame.lock_paper = true;
  frame.decimals = opt.decimals;
  open_svg_document(p, frame);

  int index = 0;
  for (const auto& layer : d.layers) {
    ++index;
    const std::string colour = layer.pen.color.hex();
    open_pen_layer(p, layer.pen.number > 0 ? layer.pen.number : index, layer.pen, opt.decimals);
    for (const auto& dot : layer.dots) push_filled_circle(p, dot.c, dot.diameter / 2, colour, opt.decimals);
    for (const auto& c : layer.circles) {
      if (c.filled) {
        push_filled_circle(p, c.c, c.r, c.fill.hex(), opt.decimals);
        continue;
      }
      p.OpenElement("circle");
      p.PushAttribute("cx", num(c.c.x).c_str());
      p.PushAttribute("cy", num(c.c.y).c_str());
      p.PushAttribute("r", num(c.r).c_str());
      p.CloseElement(true);
    }
    std::vector<const std::vector<Vec2>*> lines;
    for (const auto& pl : layer.lines)
      if (!pl.pts.empty()) lines.push_back(&pl.pts);
    push_lines(p, lines, LineElement::polyline, opt.decimals);
    for (const auto& a : layer.areas) push_area(p, a, opt.decimals);
    p.CloseElement();
  }
  p.CloseElement();
}

}  // namespace

std::string svg_string(const Drawing& drawing, const SvgOptions& opt) {
  return xml_to_string([&](tinyxml2::XMLPrinter& p) { write(drawing, p, opt); });
}

void write_svg(const Drawing& drawing, const std::string& path, const SvgOptions& opt) {
  xml_to_file_atomic(path, [&](tinyxml2::XMLPrinter& p) { write(drawing, p, opt); });
}

}  // namespace stipplot
