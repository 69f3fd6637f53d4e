#include "svg/planned_svg.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <cstdio>
#include <memory>

#include "svg/svg_writer.hpp"
#include "svg/svg_document.hpp"
#include "svg/xml_output.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot {

namespace {

void write(const Plan& plan, tinyxml2::XMLPrinter& p, const PlannedSvgOptions& opt) {
  SvgFrame frame;
  frame.page = plan.page;
  frame.title = "stipplot plan (strokes in plot order)";
  frame.paper_background = opt.paper_background;
  frame.decimals = opt.decimals;
  open_svg_document(p, frame);

  std::string d;
  int index = 0;
  for (const auto& layer : plan.layers) {
    ++index;
    const std::string colour = layer.pen.color.hex();
    open_pen_layer(p, index, layer.pen, opt.decimals);
    // Strokes in plot order: the lines between two dots go out together.
    std::vector<const std::vector<Vec2>*> lines;
    for (const auto& s : layer.strokes) {
      if (s.pts.empty()) continue;
      if (s.pts.size() == 1) {
        push_lines(p, lines, LineElement::path, opt.decimals);
        lines.clear();
        push_filled_circle(p, s.pts[0], layer.pen.width_mm / 2, colour, opt.decimals);
        continue;
      }
      lines.push_back(&s.pts);
    }
    push_lines(p, lines, LineElement::path, opt.decimals);
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
          append_number(d, last.x, opt.decimals);
          d += ',';
          append_number(d, last.y, opt.decimals);
          d += ' ';
          append_number(d, s.pts[0].x, opt.decimals);
          d += ',';
          append_number(d, s.pts[0].y, opt.decimals);
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
