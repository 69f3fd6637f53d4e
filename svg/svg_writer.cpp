#include "svg/svg_writer.hpp"

#include <tinyxml2.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "svg/xml_output.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot {

std::string format_number(double v, int decimals) {
  char buf[64];
  if (!std::isfinite(v)) throw std::logic_error("non-finite coordinate in drawing");
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

namespace {

void write(const Drawing& d, tinyxml2::XMLPrinter& p, const SvgOptions& opt) {
  auto num = [&](double v) { return format_number(v, opt.decimals); };
  p.PushHeader(false, true);
  p.OpenElement("svg");
  p.PushAttribute("xmlns", "http://www.w3.org/2000/svg");
  p.PushAttribute("xmlns:inkscape", "http://www.inkscape.org/namespaces/inkscape");
  p.PushAttribute("xmlns:sodipodi", "http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd");
  p.PushAttribute("version", "1.1");
  p.PushAttribute("width", (num(d.page.width_mm) + "mm").c_str());
  p.PushAttribute("height", (num(d.page.height_mm) + "mm").c_str());
  p.PushAttribute("viewBox", ("0 0 " + num(d.page.width_mm) + " " + num(d.page.height_mm)).c_str());
  p.OpenElement("title");
  p.PushText("stipplot drawing");
  p.CloseElement();

  if (opt.paper_background) {
    p.OpenElement("g");
    p.PushAttribute("id", "paper");
    p.PushAttribute("inkscape:groupmode", "layer");
    p.PushAttribute("inkscape:label", "% paper (not plotted)");
    p.PushAttribute("sodipodi:insensitive", "true");
    p.PushAttribute("class", "non-plotting");
    p.OpenElement("rect");
    p.PushAttribute("x", "0");
    p.PushAttribute("y", "0");
    p.PushAttribute("width", num(d.page.width_mm).c_str());
    p.PushAttribute("height", num(d.page.height_mm).c_str());
    p.PushAttribute("fill", d.page.paper.hex().c_str());
    p.PushAttribute("stroke", "none");
    p.CloseElement();
    p.CloseElement();
  }

  int index = 0;
  for (const auto& layer : d.layers) {
    ++index;
    const std::string colour = layer.pen.color.hex();
    p.OpenElement("g");
    p.PushAttribute("id", ("layer" + std::to_string(index)).c_str());
    p.PushAttribute("inkscape:groupmode", "layer");
    p.PushAttribute("inkscape:label", (std::to_string(index) + " " + layer.pen.name).c_str());
    p.PushAttribute("data-pen-width", num(layer.pen.width_mm).c_str());
    p.PushAttribute("stroke", colour.c_str());
    p.PushAttribute("stroke-width", num(layer.pen.width_mm).c_str());
    p.PushAttribute("stroke-linecap", "round");
    p.PushAttribute("stroke-linejoin", "round");
    p.PushAttribute("fill", "none");
    for (const auto& dot : layer.dots) {
      p.OpenElement("circle");
      p.PushAttribute("cx", num(dot.c.x).c_str());
      p.PushAttribute("cy", num(dot.c.y).c_str());
      p.PushAttribute("r", num(dot.diameter / 2).c_str());
      p.PushAttribute("fill", colour.c_str());
      p.PushAttribute("stroke", "none");
      p.CloseElement(true);
    }
    for (const auto& c : layer.circles) {
      p.OpenElement("circle");
      p.PushAttribute("cx", num(c.c.x).c_str());
      p.PushAttribute("cy", num(c.c.y).c_str());
      p.PushAttribute("r", num(c.r).c_str());
      if (c.filled) {
        p.PushAttribute("fill", c.fill.hex().c_str());
        p.PushAttribute("stroke", "none");
      }
      p.CloseElement(true);
    }
    std::string pts;
    for (const auto& pl : layer.lines) {
      if (pl.pts.empty()) continue;
      pts.clear();
      for (size_t i = 0; i < pl.pts.size(); ++i) {
        if (i) pts += ' ';
        pts += num(pl.pts[i].x);
        pts += ',';
        pts += num(pl.pts[i].y);
      }
      p.OpenElement("polyline");
      p.PushAttribute("points", pts.c_str());
      p.CloseElement(true);
    }
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
