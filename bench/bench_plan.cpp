// Planner benchmarks. Quality is reported as ratios against baselines
// computed in the same run; times as counters (wall and process CPU, since the
// machine is shared).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <ctime>

#include "methods/stipple/stipple.hpp"
#include "drivers/motion/time_model.hpp"
#include "spatial/mst.hpp"
#include "plan/planner.hpp"
#include "plan/tour.hpp"
#include "util/rng.hpp"

using namespace stipplot;

namespace {

std::vector<Vec2> uniform_dots(size_t n, double side, uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec2> p(n);
  for (auto& v : p) v = {rng.uniform() * side, rng.uniform() * side};
  return p;
}


struct Timer {
  std::chrono::steady_clock::time_point wall = std::chrono::steady_clock::now();
  std::clock_t cpu = std::clock();
  double wall_s() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count(); }
  double cpu_s() const { return static_cast<double>(std::clock() - cpu) / CLOCKS_PER_SEC; }
};

// A photo-like test image: smooth light, a dark disc, a bright window, text-like bars
// and a little noise.
Image synthetic_photo(int w, int h) {
  Image img;
  img.width = w;
  img.height = h;
  img.rgb.resize(static_cast<size_t>(w) * h * 3);
  Rng rng(3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double u = static_cast<double>(x) / w, v = static_cast<double>(y) / h;
      double g = 200 - 120 * v + 40 * std::sin(6 * u) * std::cos(4 * v);
      if (std::hypot(u - 0.35, v - 0.45) < 0.2) g = 40 + 60 * std::hypot(u - 0.35, v - 0.45) / 0.2;
      if (u > 0.6 && u < 0.85 && v > 0.15 && v < 0.4) g = 245;
      if (v > 0.75 && v < 0.9 && std::fmod(u * 23, 1.0) < 0.3) g = 20;
      g += (rng.uniform() - 0.5) * 20;
      const uint8_t c = static_cast<uint8_t>(std::clamp(g, 0.0, 255.0));
      for (int k = 0; k < 3; ++k) img.rgb[(static_cast<size_t>(y) * w + x) * 3 + k] = c;
    }
  return img;
}

}  // namespace

// The quality bar: 100,000 uniform random dots, pen-up travel of the plan at
// most 1.20 x the weight of their Euclidean MST, planned in at most 3 s. Baselines in
// the same run: greedy nearest neighbour alone and the dots in generation order.
static void BM_PlanUniformDots(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const auto pts = uniform_dots(n, 200, 42);
  Drawing d;
  d.layers.resize(1);
  for (const Vec2& p : pts) d.layers[0].dots.push_back({p, 0.3});
  Timer tm;
  const double mst = spatial::total_cost(spatial::euclidean_mst(pts));
  const double mst_s = tm.wall_s();
  std::vector<int32_t> partner(n, -1);
  std::vector<uint32_t> gen(n);
  for (uint32_t i = 0; i < n; ++i) gen[i] = i;
  const double generation = plan::tour_travel(pts, partner, {0, 0}, gen);
  PlanOptions nn;
  nn.optimize_seconds = 0;
  Timer tn;
  const double greedy = pen_up_travel(plan_drawing(d, nn));
  const double greedy_s = tn.wall_s();
  PlanOptions opt;  // defaults: 2 s improvement budget
  double planned = 0, wall = 0, cpu = 0;
  PlanInfo info;
  for (auto _ : state) {
    Timer t;
    const Plan p = plan_drawing(d, opt, &info);
    wall = t.wall_s();
    cpu = t.cpu_s();
    planned = pen_up_travel(p);
  }
  state.counters["ratio_planned_to_emst"] = planned / mst;
  state.counters["ratio_greedy_nn_to_emst"] = greedy / mst;
  state.counters["ratio_generation_order_to_emst"] = generation / mst;
  state.counters["plan_wall_s"] = wall;
  state.counters["plan_cpu_s"] = cpu;
  state.counters["budget_hit"] = info.budget_hit;
  state.counters["greedy_wall_s"] = greedy_s;
  state.counters["emst_wall_s"] = mst_s;
}
BENCHMARK(BM_PlanUniformDots)->Arg(100000)->Unit(benchmark::kMillisecond)->Iterations(1);

// The 2-opt/Or-opt improvement run to its local optimum (no budget), for the best
// quality this neighbourhood reaches and the time it takes.
static void BM_TourLocalOptimum(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const auto pts = uniform_dots(n, 200, 42);
  std::vector<int32_t> partner(n, -1);
  const double mst = spatial::total_cost(spatial::euclidean_mst(pts));
  plan::TourStats st;
  double planned = 0;
  for (auto _ : state) {
    plan::TourOptions opt;
    opt.seconds = 120;
    planned = plan::tour_travel(pts, partner, {0, 0}, plan::plan_tour(pts, partner, {0, 0}, opt, &st));
  }
  state.counters["ratio_to_emst"] = planned / mst;
  state.counters["construct_s"] = st.construct_seconds;
  state.counters["improve_s"] = st.improve_seconds;
  state.counters["moves_2opt"] = static_cast<double>(st.moves_2opt);
  state.counters["moves_oropt"] = static_cast<double>(st.moves_oropt);
  state.counters["budget_hit"] = st.budget_hit;
}
BENCHMARK(BM_TourLocalOptimum)->Arg(100000)->Unit(benchmark::kMillisecond)->Iterations(1);

// ~200,000 stipple dots on a photo-like image: stippling, planning and the time
// estimate in one run (`stipplot stipple ... -o x.gcode` must take under 5 s; the
// G-code writer is timed in bench_writers). Baseline: the stippling itself.
static void BM_PlanStipple(benchmark::State& state) {
  const Image img = synthetic_photo(static_cast<int>(state.range(0)), static_cast<int>(state.range(0)));
  StippleParams sp;
  sp.a = 1;
  sp.b = 4;
  Placement place;
  place.page = {420, 420};
  double stipple_s = 0, plan_s = 0, plan_cpu = 0, est_s = 0, estimate = 0, planned = 0, greedy = 0;
  size_t dots = 0;
  PlanInfo info;
  for (auto _ : state) {
    Timer t0;
    const Drawing d = stipple(img, sp, place);
    stipple_s = t0.wall_s();
    dots = d.primitive_count();
    Timer t1;
    const Plan p = plan_drawing(d, PlanOptions{}, &info);
    plan_s = t1.wall_s();
    plan_cpu = t1.cpu_s();
    planned = pen_up_travel(p);
    PlanOptions nn;
    nn.optimize_seconds = 0;
    greedy = pen_up_travel(plan_drawing(d, nn));
    Timer t2;
    estimate = estimate_seconds(p, MotionParams{});
    est_s = t2.wall_s();
  }
  state.counters["dots"] = static_cast<double>(dots);
  state.counters["stipple_wall_s"] = stipple_s;
  state.counters["plan_wall_s"] = plan_s;
  state.counters["plan_cpu_s"] = plan_cpu;
  state.counters["estimate_wall_s"] = est_s;
  state.counters["budget_hit"] = info.budget_hit;
  state.counters["travel_planned_to_greedy_nn"] = planned / greedy;
  state.counters["plot_estimate_h"] = estimate / 3600;
  state.counters["plan_to_stipple_time"] = plan_s / stipple_s;
}
BENCHMARK(BM_PlanStipple)->Arg(1530)->Unit(benchmark::kMillisecond)->Iterations(1);

// The motion model alone on a long plan (many short strokes): blocks per second.
static void BM_EstimateSeconds(benchmark::State& state) {
  Plan p;
  p.layers.resize(1);
  Rng rng(9);
  for (int i = 0; i < 20000; ++i) {
    Stroke s;
    Vec2 a{rng.uniform() * 200, rng.uniform() * 200};
    for (int k = 0; k < 10; ++k) s.pts.push_back({a.x + k * 0.3, a.y + (k % 2) * 0.3});
    p.layers[0].strokes.push_back(s);
  }
  double t = 0;
  for (auto _ : state) benchmark::DoNotOptimize(t = estimate_seconds(p, MotionParams{}));
  state.SetItemsProcessed(state.iterations() * 20000 * 10);
}
BENCHMARK(BM_EstimateSeconds)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
