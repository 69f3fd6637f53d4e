#include "svg/svg_document.hpp"

#include <algorithm>

#include "svg/svg_writer.hpp"

namespace stipplot {

void open_svg_document(tinyxml2::XMLPrinter& p, const SvgFrame& f) {
  auto num = [&](double v) { return format_number(v, f.decimals); };
  const std::string w = num(f.page.width_mm), h = num(f.page.height_mm);
  p.PushHeader(false, true);
  p.OpenElement("svg");
  p.PushAttribute("xmlns", "http://www.w3.org/2000/svg");
  p.PushAttribute("xmlns:inkscape", "http://www.inkscape.org/namespaces/inkscape");
  if (f.lock_paper) p.PushAttribute("xmlns:sodipodi", "http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd");
  p.PushAttribute("version", "1.1");
  p.PushAttribute("width", (w + "mm").c_str());
  p.PushAttribute("height", (h + "mm").c_str());
  p.PushAttribute("viewBox", ("0 0 " + w + " " + h).c_str());
  p.OpenElement("title");
  p.PushText(f.title.c_str());
  p.CloseElement();
  if (!f.paper_background) return;
  p.OpenElement("g");
  p.PushAttribute("id", "paper");
  p.PushAttribute("inkscape:groupmode", "layer");
  p.PushAttribute("inkscape:label", "% paper (not plotted)");
  if (f.lock_paper) {
    p.PushAttribute("sodipodi:insensitive", "true");
    p.PushAttribute("class", "non-plotting");
  }
  p.OpenElement("rect");
  p.PushAttribute("x", "0");
  p.PushAttribute("y", "0");
  p.PushAttribute("width", w.c_str());
  p.PushAttribute("height", h.c_str());
  p.PushAttribute("fill", f.page.paper.hex().c_str());
  p.PushAttribute("stroke", "none");
  p.CloseElement();
  p.CloseElement();
}

void open_pen_layer(tinyxml2::XMLPrinter& p, int index, const Pen& pen, int decimals) {
  const std::string width = format_number(pen.width_mm, decimals);
  p.OpenElement("g");
  p.PushAttribute("id", ("layer" + std::to_string(index)).c_str());
  p.PushAttribute("inkscape:groupmode", "layer");
  p.PushAttribute("inkscape:label", (std::to_string(index) + " " + pen.name).c_str());
  p.PushAttribute("data-pen-width", width.c_str());
  p.PushAttribute("stroke", pen.color.hex().c_str());
  p.PushAttribute("stroke-width", width.c_str());
  p.PushAttribute("stroke-linecap", "round");
  p.PushAttribute("stroke-linejoin", "round");
  p.PushAttribute("fill", "none");
}

void push_filled_circle(tinyxml2::XMLPrinter& p, Vec2 c, double r, const std::string& fill, int decimals) {
  p.OpenElement("circle");
  p.PushAttribute("cx", format_number(c.x, decimals).c_str());
  p.PushAttribute("cy", format_number(c.y, decimals).c_str());
  p.PushAttribute("r", format_number(r, decimals).c_str());
  p.PushAttribute("fill", fill.c_str());
  p.PushAttribute("stroke", "none");
  p.CloseElement(true);
}

void push_line(tinyxml2::XMLPrinter& p, const std::vector<Vec2>& pts, LineElement as, int decimals, std::string& scratch) {
  for (size_t from = 0; from < pts.size();) {
    const size_t to = std::min(pts.size(), from + kMaxElementPoints);
    scratch.clear();
    if (as == LineElement::path) scratch += 'M';
    for (size_t i = from; i < to; ++i) {
      if (as == LineElement::path && i == from + 1) scratch += " L";
      if (as == LineElement::path || i > from) scratch += ' ';
      append_number(scratch, pts[i].x, decimals);
      scratch += ',';
      append_number(scratch, pts[i].y, decimals);
    }
    p.OpenElement(as == LineElement::path ? "path" : "polyline");
    p.PushAttribute(as == LineElement::path ? "d" : "points", scratch.c_str());
    p.CloseElement(true);
    if (to == pts.size()) break;
    from = to - 1;  // the next piece starts where this one ends
  }
}

}  // namespace stipplot
