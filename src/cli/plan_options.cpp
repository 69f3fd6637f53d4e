#include "cli/plan_options.hpp"

#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::cli {

PlanOptions PlanArgs::resolve() const {
  PlanOptions o;
  require_range("--optimize-effort", optimize_effort, 0, 1000);
  require_range("--optimize-seconds (s)", optimize_seconds, 0, 3600);
  const double join_mm = parse_paper_mm(join_tolerance, "--join-tolerance");
  require_range("--join-tolerance (mm)", join_mm, 0, 10);
  o.optimize_effort = optimize_effort;
  o.optimize_seconds = optimize_seconds;
  o.fill = plan::parse_fill_mode(fill);
  o.join_tolerance_mm = join_mm;
  o.hatch_spacing_mm = parse_paper_mm(hatch_spacing, "--hatch-spacing");
  o.hatch_angle_degrees = hatch_angle;
  o.simplify_mm = parse_paper_mm(simplify, "--simplify");
  o.min_length_mm = parse_paper_mm(min_length, "--min-length");
  o.passes = passes;
  o.reloop = reloop;
  o.validate();
  return o;
}

void add_plan_options(CLI::App* cmd, PlanArgs& a) {
  cmd->add_option("--optimize-effort", a.optimize_effort,
                  "Work for improving the pen's path: perturbation trials per point (on at most 300k points) "
                  "after 2-opt/Or-opt; 0 = their local optimum only. Same input, same plan, at any load")
      ->capture_default_str()
      ->group("Planning");
  cmd->add_option("--optimize-seconds", a.optimize_seconds,
                  "Wall-clock cap on that work (only if it trips does the plan depend on the machine); "
                  "0 = greedy construction only")
      ->capture_default_str()
      ->group("Planning");
  cmd->add_option("--fill", a.fill, "Filled circles and dots wider than the pen: spiral|hatch|none")
      ->capture_default_str()
      ->group("Planning");
  cmd->add_option("--join-tolerance", a.join_tolerance, "Polyline ends closer than this are joined: mm (0.05, 0.05mm), cm, in, pt or px (1/96 in)")
      ->capture_default_str()
      ->group("Planning");
  cmd->add_option("--hatch-spacing", a.hatch_spacing,
                  "Filled shapes: hatch lines this far apart (a length); 0 = 0.9 x the pen width, solid")
      ->capture_default_str()
      ->group("Planning");
  cmd->add_option("--hatch-angle", a.hatch_angle, "Filled shapes: hatch angle in degrees, clockwise from across")
      ->capture_default_str()
      ->group("Planning");
  const char* g = "Paths";
  cmd->add_option("--simplify", a.simplify, "Simplify lines within this tolerance (a length, 0.05mm); 0 = off")
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--min-length", a.min_length, "Leave out strokes shorter than this (a length, 0.5mm); dots stay")
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--multipass", a.passes, "Draw every stroke this many times without lifting")
      ->capture_default_str()
      ->group(g);
  cmd->add_flag("--reloop", a.reloop, "Start closed paths where the pen's travel to them is shortest")->group(g);
}

}  // namespace stipplot::cli
