#pragma once
// Options of every command that plans a drawing for a plotter (export, -o x.gcode,
// plot), so --optimize-effort, --optimize-seconds and --fill mean the same everywhere.
#include <CLI/CLI.hpp>
#include <string>

#include "plan/planner.hpp"

namespace stipplot::cli {

struct PlanArgs {
  double optimize_effort = PlanOptions{}.optimize_effort;
  double optimize_seconds = PlanOptions{}.optimize_seconds;
  std::string fill = "spiral";
  std::string join_tolerance = "0.05";
  std::string hatch_spacing = "0", simplify = "0", min_length = "0";
  double hatch_angle = 45;
  int passes = 1;
  bool reloop = false;
  PlanOptions resolve() const;  // throws UserError naming the option
};

// Adds --optimize-effort, --optimize-seconds, --fill, --join-tolerance, --hatch-spacing and
// --hatch-angle in a "Planning" group, and the path operations --simplify, --min-length,
// --multipass and --reloop in a "Paths" group.
void add_plan_options(CLI::App* cmd, PlanArgs& a);

}  // namespace stipplot::cli
