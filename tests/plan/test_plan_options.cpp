#include <catch2/catch.hpp>

#include <cmath>

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

TEST_CASE("the optimisation effort is the work budget, the seconds only its cap", "[plan][cli]") {
  CLI::App app;
  cli::PlanArgs a;
  cli::add_plan_options(&app, a);
  app.parse("", false);
  CHECK(a.resolve().optimize_effort == PlanOptions{}.optimize_effort);
  CHECK(a.resolve().optimize_seconds == PlanOptions{}.optimize_seconds);
  app.parse("--optimize-effort 2.5", false);
  CHECK(a.resolve().optimize_effort == 2.5);
  a.optimize_effort = -1;
  CHECK_THROWS_WITH(a.resolve(), Catch::Contains("--optimize-effort"));
  PlanOptions o;
  o.optimize_effort = std::nan("");
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("--optimize-effort"));
}
