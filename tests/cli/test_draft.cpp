// --draft, the studio's quick look while a control moves: the page grid at the preview's
// pixel, the tour without trials; the drawing reads and times as the full run's does.
#include <catch2/catch.hpp>

#include "cli_json.hpp"
#include "test_util.hpp"

TEST_CASE("stipple --draft: a grid no finer than the preview's pixel, the full run's time and look", "[cli][draft]") {
  test::TempDir t;
  const std::string common = "stipple " + test::example("coffee.png") + " --profile=grbl-servo --seed 5 --measure";
  const auto full = test::run_json(common + " -o " + t.file("full.svg"));
  const auto draft = test::run_json(common + " -o " + t.file("draft.svg") + " --draft --preview-dpi 80 --preview " +
                                    t.file("draft.png"));
  INFO(full.dump() << "\n" << draft.dump());
  CHECK(draft["cell_mm"].get<double>() >= 0.99 * 25.4 / 80);  // whole cells across the page
  CHECK(full["cell_mm"].get<double>() < 25.4 / 80);
  const double cells_full = full["grid"][0].get<double>() * full["grid"][1].get<double>();
  const double cells_draft = draft["grid"][0].get<double>() * draft["grid"][1].get<double>();
  CHECK(cells_draft < cells_full / 2);
  CHECK(draft["style"] == full["style"]);
  // The same budget, met; a plot time and a view from arm's length close to the full run's.
  const double tf = full["plan"]["total"]["seconds"], td = draft["plan"]["total"]["seconds"];
  CHECK(td <= 3600 * 1.01);
  CHECK(std::abs(td - tf) < 0.1 * tf);
  CHECK(std::abs(draft["ssim_view"].get<double>() - full["ssim_view"].get<double>()) < 0.05);
  CHECK(std::filesystem::exists(t.file("draft.png")));
}
