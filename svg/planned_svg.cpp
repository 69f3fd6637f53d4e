#include "svg/planned_svg.hpp"

#include <tinyxml2.h>

#include <cstdio>
#include <memory>

#include "svg/svg_writer.hpp"
#include "svg/xml_output.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot {

namespace {

void write(const Plan& plan, tinyxml2::XMLPrinter& p, const PlannedSvgOptions& opt) {
  auto num = [&](double v) { return format_number(v, opt.decimals); };
  const Page& page = plan.page;
  p.PushHeader(false, true);
  p.OpenElement("svg");
  p.PushAttribute("xmlns", "http://www.w3.org/2000/svg");
  p.PushAttribute("xmlns:inkscape", "http://www.inkscape.org/namespaces/inkscape");
  p.PushAttribute("version", "1.1");
  p.PushAttribute("width", (num(page.width_mm) + "mm").c_str());
  p.PushAttribute("height", (num(page.height_mm) + "mm").c_str());
  p.PushAttribute("viewBox", ("0 0 " + num(page.width_mm) + " " + num(page.height_mm)).c_str());
  p.OpenElement("title");
  p.PushText("stipplot plan (strokes in plot order)");
  p.CloseElement();
  if (opt.paper_background) {
    p.OpenElement("g");
    p.PushAttribute("id", "paper");
    p.PushAttribute("inkscape:groupmode", "layer");
    p.PushAttribute("inkscape:label", "% paper (not plotted)");
    p.OpenElement("rect");
    p.PushAttribute("x", "0");
    p.PushAttribute("y", "0");
    p.PushAttribute("width", num(page.width_mm).c_str());
    p.PushAttribute("height", num(page.height_mm).c_str());
    p.PushAttribute("fill", page.paper.hex().c_str());
    p.PushAttribute("stroke", "none");
    p.CloseElement();
    p.CloseElement();
  }

  std::string d;
  int index = 0;
  for (const auto& layer : plan.layers) {
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
    for (const auto& s : layer.strokes) {
      if (s.pts.empty()) continue;
      if (s.pts.size() == 1) {
        p.OpenElement("circle");
        p.PushAttribute("cx", num(s.pts[0].x).c_str());
        p.PushAttribute("cy", num(s.pts[0].y).c_str());
        p.PushAttribute("r", num(layer.pen.width_mm / 2).c_str());
        p.PushAttribute("fill", colour.c_str());
        p.PushAttribute("stroke", "none");
        p.CloseElement(true);
        continue;
      }
      d.clear();
      d += 'M';
      for (size_t i = 0; i < s.pts.size(); ++i) {
        if (i == 1) d += " L";
        d += ' ';
        d += num(s.pts[i].x);
        d += ',';
        d += num(s.pts[i].y);
      }
      p.OpenElement("path");
      p.PushAttribute("d", d.c_str());
      p.CloseElement(true);
    }
    p.CloseElement();
  }

  if (opt.show_travel) {
    // Pen-up moves: from the end of each stroke to the start of the next, across layers.
    p.OpenElement("g");
    p.PushAttribute("id", "travel");
    p.PushAttribute("inkscape:groupmode", "layer");
    p.PushAttribute("inkscape:label", "% travel (pen up, not plotted)");
    p.PushAttribute("style", "display:none");
    p.PushAttribute("stroke", "#ff0000");
    p.PushAttribute("stroke-width", "0.1");
    p.PushAttribute("fill", "none");
    bool have = false;
    Vec2 last;
    d.clear();
    for (const auto& layer : plan.layers) {
      for (const auto& s : layer.strokes) {
        if (s.pts.empty()) continue;
        if (have) {
          d += d.empty() ? "M " : " M ";
          d += num(last.x);
          d += ',';
          d += num(last.y);
          d += ' ';
          d += num(s.pts[0].x);
          d += ',';
          d += num(s.pts[0].y);
        }
        last = s.pts.back();
        have = true;
      }
    }
    if (!d.empty()) {
      p.OpenElement("path");
      p.PushAttribute("d", d.c_str());
      p.CloseElement(true);
    }
    p.CloseElement();
  }
  p.CloseElement();
}

}  // namespace

std::string planned_svg_string(const Plan& plan, const PlannedSvgOptions& opt) {
  return xml_to_string([&](tinyxml2::XMLPrinter& p) { write(plan, p, opt); });
}

void write_planned_svg(const Plan& plan, const std::string& path, const PlannedSvgOptions& opt) {
  xml_to_file_atomic(path, [&](tinyxml2::XMLPrinter& p) { write(plan, p, opt); });
}

}  // namespace stipplot
