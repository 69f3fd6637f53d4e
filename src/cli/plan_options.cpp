#include "cli/plan_options.hpp"

#include "util/error.hpp"

namespace stipplot::cli {

PlanOptions PlanArgs::resolve() const {
  PlanOptions o;
  require_range("--optimize-seconds", optimize_seconds, 0, 3600);
  require_range("--join-tolerance", join_tolerance, 0, 10);
  o.optimize_seconds = optimize_seconds;
  o.fill = plan::parse_fill_mode(fill);
  o.join_tolerance_mm = join_tolerance;
  o.validate();
  return o;
}

void add_plan_options(CLI::App* cmd, PlanArgs& a) {
  cmd->add_option("--optimize-seconds", a.optimize_seconds,
                  "Time for improving the pen's path (2-opt/Or-opt); 0 = nearest neighbour only")
      ->capture_default_str()
      ->group("Planning");
  cmd->add_option("--fill", a.fill, "Filled circles and dots wider than the pen: spiral|hatch|none")
      ->capture_default_str()
      ->group("Planning");
  cmd->add_option("--join-tolerance", a.join_tolerance, "Polyline ends closer than this (mm) are joined")
      ->capture_default_str()
      ->group("Planning");
}

}  // namespace stipplot::cli
