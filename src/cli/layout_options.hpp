#pragma once
// Options of every command that lays a drawing out for a device (export, plot, and the
// method commands with -o x.gcode/x.hpgl or --profile): which layers, which pens, and
// where on the sheet (layout/layout.hpp), so --fit and --pen-map mean the same everywhere.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "drivers/device/profile.hpp"
#include "geometry/drawing.hpp"
#include "layout/layout.hpp"

namespace stipplot::cli {

struct LayoutArgs {
  std::string page;             // empty: the profile's sheet
  std::string margin = "10";    // for --fit and --align
  bool fit = false, center = false, no_rotate = false;
  std::string scale = "1", align, rotate, crop;
  std::string layers, pen_map;
  // Which of them the user gave: without any, a method's SVG needs no layout.
  bool any_given() const;
};

// Adds --fit, --scale, --align/--center, --rotate, --no-rotate, --crop, --layer and
// --pen-map in a "Layout" group; with `page_options`, also --page and --margin (method
// commands have their own, which the layout then uses).
void add_layout_options(CLI::App* cmd, LayoutArgs& a, bool page_options);

// Everything checked before any work: lengths, the alignment, the crop rectangle.
void check_layout_args(const LayoutArgs& a);

// The drawing's layers chosen and pens mapped, then laid out on the sheet: --page (a named
// size turned like the device's sheet, WxH as given) or the device's sheet, within its
// reach; without a device, on the drawing's own page. `margin_mm` < 0 takes --margin.
// Adds a "layout" object to `summary` and returns what the result line should say ("" if
// nothing worth saying).
Drawing lay_out_for_device(Drawing d, const LayoutArgs& a, const DeviceProfile* device, double margin_mm,
                           nlohmann::json& summary, std::string& phrase);

// The sheet a drawing goes on for `device` (see lay_out_for_device), in its orientation.
Page sheet_for(const LayoutArgs& a, const DeviceProfile& device);

// The widest border of the sheet the device cannot reach: a method's margin is at least
// this, so its drawing lands inside the travel whichever way it is turned.
double unreachable_border_mm(const DeviceProfile& device, const Page& sheet);

}  // namespace stipplot::cli
