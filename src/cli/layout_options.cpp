#include "cli/layout_options.hpp"

#include <algorithm>
#include <cctype>

#include "drivers/device/machine.hpp"
#include "geometry/page.hpp"
#include "layout/layers.hpp"
#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::cli {

bool LayoutArgs::any_given() const {
  return !page.empty() || fit || center || no_rotate || scale != "1" || !align.empty() || !rotate.empty() ||
         !crop.empty() || !layers.empty() || !pen_map.empty();
}

void add_layout_options(CLI::App* cmd, LayoutArgs& a, bool page_options) {
  const char* g = "Layout";
  if (page_options) {
    cmd->add_option("--page", a.page,
                    "Sheet: A4, A3, letter... (turned as the profile's sheet lies) or WxH (297x210mm, 11x8.5in); "
                    "default: the profile's sheet")
        ->group(g);
    cmd->add_option("--margin", a.margin, "Margin kept by --fit and --align: mm (10, 10mm), cm, in, pt or px (1/96 in)")
        ->capture_default_str()->group(g);
  }
  cmd->add_flag("--fit", a.fit, "Scale the drawing, keeping its aspect, to fill the sheet less the margins (and the device's reach)")
      ->group(g);
  cmd->add_option("--scale", a.scale, "Scale the drawing by this factor (0.5, 2)")->capture_default_str()->group(g);
  cmd->add_option("--align", a.align,
                  "Put the drawing at center, top, bottom, left, right, top-left, ... of the sheet less the margins "
                  "(--fit centres by default)")
      ->group(g);
  cmd->add_flag("--center", a.center, "Same as --align center")->group(g);
  cmd->add_option("--rotate", a.rotate, "Rotate the drawing clockwise by DEG degrees (90, -90, 180, 30)")->group(g);
  cmd->add_flag("--no-rotate", a.no_rotate,
                "Do not turn a drawing whose orientation differs from the sheet's (turned 90° by default)")
      ->group(g);
  cmd->add_option("--crop", a.crop, "Keep only X,Y,W,H of the drawing's own page (lengths: 10,10,100,50mm)")->group(g);
  cmd->add_option("--layer", a.layers, "Draw only these layers: numbers or names, 1,3 or outline,2")->group(g);
  cmd->add_option("--pen-map", a.pen_map,
                  "Pens for layers: LAYER=PEN items, a layer by number, name or stroke colour (red=2,#0000ff=3,1=1); "
                  "layers on one pen are drawn together")
      ->group(g);
}

namespace {

double parse_factor(const std::string& text, const char* option) {
  double v = 0;
  std::string unit;
  if (!split_number_unit(text, v, unit) || !unit.empty() || !std::isfinite(v))
    throw UserError(std::string(option) + ": expected a number, got '" + text + "'");
  return v;
}

// "X,Y,W,H" with a unit after the last number for all four ("10,10,100,50mm"), or each its own.
Rect parse_crop(const std::string& text) {
  std::vector<std::string> parts;
  size_t pos = 0;
  while (true) {
    const size_t comma = text.find(',', pos);
    parts.push_back(text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos));
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  if (parts.size() != 4) throw UserError("--crop: expected X,Y,W,H such as 10,10,100,50mm, got '" + text + "'");
  std::string shared_unit;
  double v;
  if (!split_number_unit(parts[3], v, shared_unit)) shared_unit.clear();
  double n[4];
  for (int i = 0; i < 4; ++i) {
    std::string unit;
    if (!split_number_unit(parts[i], v, unit) || !std::isfinite(v))
      throw UserError("--crop: expected X,Y,W,H such as 10,10,100,50mm, got '" + text + "'");
    const double f = mm_per_unit(unit.empty() ? shared_unit : unit);
    if (f == 0) throw UserError("--crop: unknown unit in '" + text + "' (use mm, cm, in, pt or px)");
    n[i] = v * f;
  }
  if (!(n[2] > 0 && n[3] > 0)) throw UserError("--crop: the width and height must be positive, got '" + text + "'");
  return {n[0], n[1], n[0] + n[2], n[1] + n[3]};
}

layout::LayoutOptions layout_options(const LayoutArgs& a) {
  layout::LayoutOptions o;
  o.margin_mm = parse_paper_mm(a.margin, "--margin");
  o.fit = a.fit;
  o.scale = parse_factor(a.scale, "--scale");
  if (!(o.scale > 0)) throw UserError("--scale must be positive, got '" + a.scale + "'");
  if (!a.align.empty() && a.center) throw UserError("--align and --center exclude each other");
  if (!a.align.empty()) o.align = layout::parse_align(a.align);
  if (a.center) o.align = layout::Align::center;
  if (!a.rotate.empty()) o.rotate_degrees = parse_factor(a.rotate, "--rotate");
  o.auto_rotate = !a.no_rotate;
  if (!a.crop.empty()) o.crop = parse_crop(a.crop);
  return o;
}

// "A4", "letter": a paper name, not a WxH size.
bool is_named_page(const std::string& text) {
  return std::none_of(text.begin(), text.end(), [](unsigned char c) { return std::tolower(c) == 'x'; });
}

}  // namespace

void check_layout_args(const LayoutArgs& a) {
  layout::LayoutOptions o = layout_options(a);
  if (!a.page.empty()) (void)parse_page(a.page);
  o.sheet = {1000, 1000, colors::white};
  o.validate();
}

Page sheet_for(const LayoutArgs& a, const DeviceProfile& device) {
  Page sheet;
  sheet.width_mm = device.machine.sheet_width_mm;
  sheet.height_mm = device.machine.sheet_height_mm;
  if (a.page.empty()) return sheet;
  const PageSpec p = parse_page(a.page);
  const bool device_landscape = sheet.width_mm > sheet.height_mm;
  sheet.width_mm = p.width_mm;
  sheet.height_mm = p.height_mm;
  // A named size is paper you load the way the machine takes its own sheet.
  if (is_named_page(a.page) && (sheet.width_mm > sheet.height_mm) != device_landscape)
    std::swap(sheet.width_mm, sheet.height_mm);
  return sheet;
}

double unreachable_border_mm(const DeviceProfile& device, const Page& sheet) {
  const Rect r = MachineTransform(device, sheet).reach_on_page();
  return std::max({r.x0, r.y0, sheet.width_mm - r.x1, sheet.height_mm - r.y1, 0.0});
}

Drawing lay_out_for_device(Drawing d, const LayoutArgs& a, const DeviceProfile* device, double margin_mm,
                           nlohmann::json& summary, std::string& phrase) {
  layout::LayoutOptions o = layout_options(a);
  if (margin_mm >= 0) o.margin_mm = margin_mm;
  if (!a.pen_map.empty()) layout::apply_pen_map(d, a.pen_map);
  if (!a.layers.empty()) layout::keep_layers(d, a.layers);
  if (device) {
    o.sheet = sheet_for(a, *device);
    o.reach = MachineTransform(*device, o.sheet).reach_on_page();
  } else {
    o.sheet = d.page;
    if (!a.page.empty()) {
      const PageSpec p = parse_page(a.page);
      o.sheet.width_mm = p.width_mm;
      o.sheet.height_mm = p.height_mm;
    }
  }
  o.sheet.paper = d.page.paper;
  layout::LayoutReport rep;
  Drawing out = layout::lay_out(std::move(d), o, &rep);
  summary["layout"] = {{"sheet_mm", {o.sheet.width_mm, o.sheet.height_mm}},
                       {"rotated_degrees", rep.rotated_degrees},
                       {"auto_rotated", rep.auto_rotated},
                       {"scale", rep.scale},
                       {"margin_mm", o.margin_mm},
                       {"cropped", rep.cropped.total()},
                       {"clipped_cut", rep.clipped.cut},
                       {"clipped_dropped", rep.clipped.dropped},
                       // The drawing's page -> the sheet (x' = a x + c y + e, y' = b x + d y + f):
                       // how the studio draws a plot's progress over the method's preview.
                       {"transform", {rep.transform.a, rep.transform.b, rep.transform.c, rep.transform.d,
                                      rep.transform.e, rep.transform.f}}};
  phrase = layout::describe(rep);
  return out;
}

}  // namespace stipplot::cli
