// Tone hatching. Run: ./build/bench/bench_hatch
//  - BM_HatchToneMap: coffee.png on A4 at a 0.3 mm pen: the working grid, blur and bands
//    alone (the baseline: what any tone method pays to see the photo on paper).
//  - BM_HatchDrawing: the whole method at its finest (tone map, spacings, every
//    direction's lines clipped and linked into zig-zags); counters strokes and
//    runs_per_stroke (clipped lines a pen-down draws: the pen lifts it saves).
//  - BM_HatchPlan: planning that drawing at the default effort (what follows the method);
//    counter plot_s, its quick plot estimate on grbl-servo.
//  - BM_HatchPlanUnlinked: the same lines with every zig-zag cut back into its runs (what
//    the planner would get without the links): plot_s and strokes against BM_HatchPlan's.
// RATIO lines: the tone map against the whole method, the plan against the method.
#include <filesystem>

#include "budget/mark_costs.hpp"
#include "drivers/device/profile.hpp"
#include "methods/hatch/hatch.hpp"
#include "plan/planner.hpp"
#include "ratio_reporter.hpp"

namespace {

using namespace stipplot;

const Image& photo() {
  static const Image img =
      load_image((std::filesystem::path(__FILE__).parent_path().parent_path() / "examples" / "coffee.png").string());
  return img;
}

void BM_HatchToneMap(benchmark::State& state) {
  const hatch::HatchParams p;
  size_t cells = 0;
  for (auto _ : state) {
    const hatch::ToneMap t = hatch::tone_map(photo(), p, Placement{});
    cells = t.band.size();
    benchmark::DoNotOptimize(t.band.data());
  }
  state.counters["cells"] = double(cells);
}
BENCHMARK(BM_HatchToneMap)->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_HatchDrawing(benchmark::State& state) {
  const hatch::HatchParams p;
  Drawing d;
  for (auto _ : state) d = hatch::hatch_drawing(photo(), p, Placement{});
  size_t strokes = 0, runs = 0;
  for (const Layer& l : d.layers)
    for (const Polyline& pl : l.lines) ++strokes, runs += pl.pts.size() / 2;
  state.counters["strokes"] = double(strokes);
  state.counters["runs_per_stroke"] = strokes ? double(runs) / double(strokes) : 0;
}
BENCHMARK(BM_HatchDrawing)->Unit(benchmark::kMillisecond)->Iterations(3);

// Every stroke cut into the runs it links (even segments are lines, odd ones links).
Drawing unlinked(const Drawing& d) {
  Drawing out = d;
  for (Layer& l : out.layers) {
    std::vector<Polyline> runs;
    for (const Polyline& pl : l.lines)
      for (size_t i = 0; i + 1 < pl.pts.size(); i += 2) runs.push_back(Polyline{{pl.pts[i], pl.pts[i + 1]}});
    l.lines = std::move(runs);
  }
  return out;
}

void plan_bench(benchmark::State& state, const Drawing& d) {
  for (auto _ : state) {
    const Plan plan = plan_drawing(d, PlanOptions{});
    benchmark::DoNotOptimize(plan.layers.data());
  }
  const DeviceProfile prof = find_profile("grbl-servo");
  state.counters["plot_s"] = budget::quick_estimate_seconds(d, prof.motion, PlanOptions{});
  state.counters["strokes"] = double(d.primitive_count());
}

void BM_HatchPlan(benchmark::State& state) {
  plan_bench(state, hatch::hatch_drawing(photo(), hatch::HatchParams{}, Placement{}));
}
BENCHMARK(BM_HatchPlan)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_HatchPlanUnlinked(benchmark::State& state) {
  plan_bench(state, unlinked(hatch::hatch_drawing(photo(), hatch::HatchParams{}, Placement{})));
}
BENCHMARK(BM_HatchPlanUnlinked)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

STIPPLOT_BENCH_MAIN({{"BM_HatchToneMap", "BM_HatchDrawing"}, {"BM_HatchPlan", "BM_HatchDrawing"},
                     {"BM_HatchPlan", "BM_HatchPlanUnlinked"}})
