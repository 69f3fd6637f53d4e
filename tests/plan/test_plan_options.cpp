#include <catch2/catch.hpp>

#include "cli/plan_options.hpp"
#include "util/error.hpp"

using namespace stipplot;

TEST_CASE("plan options parse and validate", "[plan][cli]") {
  CLI::App app;
  cli::PlanArgs a;
  cli::add_plan_options(&app, a);
  app.parse("--optimize-seconds 0.5 --fill hatch", false);
  const PlanOptions o = a.resolve();
  CHECK(o.optimize_seconds == 0.5);
  CHECK(o.fill == plan::FillMode::Hatch);
  a.fill = "zigzag";
  CHECK_THROWS_AS(a.resolve(), UserError);
  a.fill = "none";
  a.optimize_seconds = -2;
  CHECK_THROWS_WITH(a.resolve(), Catch::Contains("--optimize-seconds"));
}
