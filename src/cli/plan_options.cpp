#include "cli/plan_options.hpp"

#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::cli {

PlanOptions PlanArgs::resolve() const {
  PlanOptions o;
  require_range("--optimize-seconds", optimize_seconds, 0, 3600);
  const double join_mm = parse_paper_mm(join_tolerance, "--join-tolerance");
  require_range("--join-tolerance", join_mm, 0, 10);
  o.optimize_seconds = optimize_seconds;
  o.fill = plan::parse_fill_mode(fill);
  o.join_tolerance_mm = join_mm;
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
  cmd->add_option("--join-tolerance", a.join_tolerance, "Polyline ends closer than this are joined: mm (0.05, 0.05mm), cm, in, pt or px (1/96 in)")
      ->capture_default_str()
      ->group("Planning");
}

}  // namespace stipplot::cli
