// The viewing-distance measure (eval/view.hpp) of a drawing of coffee.png on A4: ~60k dots
// sized for the photo's tone on a 0.8 mm grid, planned once. Run: ./build/bench/bench_view
//  - BM_ViewDrawing: the budget search's call, the drawing's primitives rendered at
//    4 px/mm, sigma 1 mm (view_score_of_drawing).
//  - BM_ViewCheap: the plan rendered pen-true at 4 px/mm; BM_RenderCheap: that render alone.
//  - BM_ViewCli: what --measure and `stipplot eval` do, the plan at 10 px/mm.
//  - BM_ViewCompare/threads:N: the comparison alone of the 10 px/mm render, on N threads.
//  - BM_QuickEstimate: what the search already pays for each run it tries (the quick plan
//    estimate of the same drawing): the search's measure should cost no more than it.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>

#include "budget/mark_costs.hpp"
#include "drivers/device/profile.hpp"
#include "eval/view.hpp"
#include "plan/planner.hpp"
#include "preview/preview.hpp"
#include "ratio_reporter.hpp"
#include "util/threads.hpp"

using namespace stipplot;

namespace {

struct Fixture {
  Image photo;
  PageTransform tf;
  Drawing drawing;
  Plan plan;
  Fixture() {
    namespace fs = std::filesystem;
    photo = load_image((fs::path(__FILE__).parent_path().parent_path() / "examples" / "coffee.png").string());
    tf = PageTransform(photo.width, photo.height, PageSpec{297, 210}, 10, false);
    drawing.page = {297, 210};
    Layer l;
    const double pitch = 0.8;
    const Vec2 lo = tf.map(0, 0), hi = tf.map(photo.width, photo.height);
    for (double y = lo.y + pitch / 2; y < hi.y; y += pitch)
      for (double x = lo.x + pitch / 2; x < hi.x; x += pitch) {
        const Vec2 p = tf.unmap({x, y});
        const double dark = 1 - photo.channel(static_cast<int>(p.x), static_cast<int>(p.y), 1) / 255.0;
        if (dark > 0.02) l.dots.push_back({{x, y}, pitch * std::sqrt(4 * dark / M_PI)});
      }
    drawing.layers.push_back(l);
    plan = plan_drawing(drawing, PlanOptions{});
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

void view_at(benchmark::State& state, double px_per_mm) {
  const Fixture& f = fixture();
  ViewOptions o;
  o.sigma_mm = 1;
  for (auto _ : state) benchmark::DoNotOptimize(view_score_of_plan(f.photo, f.tf, f.plan, o, px_per_mm).ssim);
  state.counters["dots"] = static_cast<double>(f.drawing.layers[0].dots.size());
}

void BM_ViewCheap(benchmark::State& state) { view_at(state, 4); }

void BM_ViewDrawing(benchmark::State& state) {
  const Fixture& f = fixture();
  ViewOptions o;
  o.sigma_mm = 1;
  for (auto _ : state) benchmark::DoNotOptimize(view_score_of_drawing(f.photo, f.tf, f.drawing, o, 4).ssim);
}
void BM_ViewCli(benchmark::State& state) { view_at(state, 10); }

// The render alone, at the cheap call's 4 px/mm: what the comparison adds to it.
void BM_RenderCheap(benchmark::State& state) {
  PreviewOptions po;
  po.dpi = 4 * 25.4;
  for (auto _ : state) benchmark::DoNotOptimize(render_plan(fixture().plan, po).rgb.data());
}

// The comparison alone (blur, SSIM, tone) of the 10 px/mm render, made once, on 1 and 2
// threads (wall-clock): the same figures bit for bit (tests "[threads]").
void BM_ViewCompare(benchmark::State& state) {
  const Fixture& f = fixture();
  static const Image page = [&] {
    PreviewOptions po;
    po.dpi = 10 * 25.4;
    return render_plan(f.plan, po);
  }();
  ViewOptions o;
  o.sigma_mm = 1;
  set_thread_count(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(view_score(f.photo, f.tf, page, o).ssim);
  set_thread_count(0);
}

void BM_QuickEstimate(benchmark::State& state) {
  const Fixture& f = fixture();
  const DeviceProfile prof = find_profile("grbl-servo");
  for (auto _ : state) benchmark::DoNotOptimize(budget::quick_estimate_seconds(f.drawing, prof.motion, PlanOptions{}));
}

}  // namespace

BENCHMARK(BM_ViewDrawing)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ViewCheap)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ViewCli)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ViewCompare)->ArgName("threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RenderCheap)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QuickEstimate)->Unit(benchmark::kMillisecond);

STIPPLOT_BENCH_MAIN({{"BM_ViewCompare/threads:2", "BM_ViewCompare/threads:1"}, {"BM_ViewDrawing", "BM_ViewCli"}, {"BM_ViewDrawing", "BM_QuickEstimate"},
                     {"BM_ViewCheap", "BM_ViewCli"}, {"BM_ViewCheap", "BM_RenderCheap"}})
