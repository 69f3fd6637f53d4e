#pragma once
// SVG of a Plan in plot order: one Inkscape layer per planned layer (pen), holding one
// <path> per stroke in the order the pen draws them (single-point strokes as dots, a
// <circle> of the pen's width), and optionally the pen-up travel as a path on a separate
// layer hidden with display:none and labelled with '%' so plotting tools skip it.
#include <string>

#include "plan/plan.hpp"

namespace stipplot {

struct PlannedSvgOptions {
  bool show_travel = false;  // add the hidden pen-up travel layer
  bool paper_background = true;
  int decimals = 3;
};

// O(total points); streams to disk, written atomically.
void write_planned_svg(const Plan& plan, const std::string& path, const PlannedSvgOptions& opt = {});
std::string planned_svg_string(const Plan& plan, const PlannedSvgOptions& opt = {});

}  // namespace stipplot
