// Planner benchmarks. Quality is reported as ratios against baselines
// computed in the same run; times as counters (wall and process CPU, since the
// machine is shared).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <map>
#include <string>

#include "drivers/device/machine.hpp"
#include "drivers/device/profile.hpp"
#include "image/image.hpp"
#include "methods/stipple/stipple.hpp"
#include "previous_tour.hpp"
#include "drivers/motion/time_model.hpp"
#include "spatial/mst.hpp"
#include "svg/svg_reader.hpp"
#include "plan/planner.hpp"
#include "plan/strokes.hpp"
#include "plan/tour.hpp"
#include "synthetic.hpp"
#include "util/rng.hpp"
#include "util/threads.hpp"

using namespace stipplot;

namespace {

using bench::uniform_dots;

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

namespace {

struct Instance {
  std::vector<Vec2> pts;
  std::vector<int32_t> partner;
  double emst = 0;
};

// Uniform dots on a 200 mm square with their Euclidean MST weight, made once per size.
const Instance& uniform_instance(size_t n) {
  static std::map<size_t, Instance> made;
  auto it = made.find(n);
  if (it != made.end()) return it->second;
  Instance in;
  in.pts = uniform_dots(n, 200, 42);
  in.partner.assign(n, -1);
  in.emst = spatial::total_cost(spatial::euclidean_mst(in.pts));
  return made.emplace(n, std::move(in)).first->second;
}

Drawing dots_drawing(const std::vector<Vec2>& pts) {
  Drawing d;
  d.page = {200, 200};
  d.layers.resize(1);
  for (const Vec2& p : pts) d.layers[0].dots.push_back({p, 0.3});
  return d;
}

// plan_drawing under the benchmark's loop (one iteration), with its CPU seconds.
Plan timed_plan(benchmark::State& state, const Drawing& d, const PlanOptions& opt, double& cpu,
                PlanInfo* info = nullptr) {
  Plan p;
  for (auto _ : state) {
    Timer t;
    p = plan_drawing(d, opt, info);
    cpu = t.cpu_s();
  }
  return p;
}

}  // namespace

// The planner on n uniform random dots, as the commands run it (default options:
// greedy edge, 2-opt/Or-opt to a local optimum, 0.3 perturbation trials a point up to
// 300k points). Quality: pen-up travel / EMST weight (targets: <= 1.16 at 10k-300k,
// <= 1.17 at 1M). Baselines in the same process: greedy nearest neighbour alone, and the
// previous planner (nearest neighbour + 2-opt/Or-opt under its 2 s wall-clock budget).
// Times are CPU seconds (the machine is shared), per point for the scaling.
static void BM_PlanUniformDots(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const Instance& in = uniform_instance(n);
  const Drawing d = dots_drawing(in.pts);
  double cpu = 0;
  PlanInfo info;
  const double planned = pen_up_travel(timed_plan(state, d, PlanOptions{}, cpu, &info));
  const double wall = info.seconds;
  plan::TourOptions nn;
  nn.start = plan::TourStart::NearestNeighbour;
  nn.improve = false;
  Timer tn;
  const double greedy = plan::tour_travel(in.pts, in.partner, {0, 0}, plan::plan_tour(in.pts, in.partner, {0, 0}, nn));
  const double greedy_cpu = tn.cpu_s();
  Timer tp;
  bench::previous::PreviousTourStats prev_st;
  const double previous = plan::tour_travel(
      in.pts, in.partner, {0, 0}, bench::previous::previous_tour(in.pts, in.partner, {0, 0}, 2.0, &prev_st));
  const double previous_cpu = tp.cpu_s(), previous_wall = tp.wall_s();
  state.counters["ratio_planned_to_emst"] = planned / in.emst;
  state.counters["ratio_greedy_nn_to_emst"] = greedy / in.emst;
  state.counters["ratio_previous_to_emst"] = previous / in.emst;
  state.counters["plan_cpu_s"] = cpu;
  state.counters["plan_wall_s"] = wall;
  state.counters["plan_cpu_us_per_point"] = 1e6 * cpu / static_cast<double>(n);
  state.counters["plan_cpu_to_greedy_nn_cpu"] = cpu / greedy_cpu;
  state.counters["previous_cpu_s"] = previous_cpu;
  state.counters["previous_wall_s"] = previous_wall;
  state.counters["previous_budget_hit"] = prev_st.budget_hit;
  state.counters["budget_hit"] = info.budget_hit;
}
BENCHMARK(BM_PlanUniformDots)->Arg(10000)->Arg(100000)->Arg(300000)->Arg(1000000)->Unit(benchmark::kMillisecond)->Iterations(1);

// One tour of 100,000 uniform dots (as the connected stipple's) on 1 and 2 threads
// (range(0)): wall time of the construction and of the improvement apart, the path the
// same on both (tests "[threads]"). Real time: the second thread's work is not the caller's.
static void BM_TourThreads(benchmark::State& state) {
  const Instance& in = uniform_instance(100000);
  set_thread_count(static_cast<int>(state.range(0)));
  plan::TourStats st;
  double construct = 0, improve = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(plan::plan_tour(in.pts, in.partner, {0, 0}, plan::TourOptions{}, &st).data());
    construct += st.construct_seconds, improve += st.improve_seconds;
  }
  set_thread_count(0);
  const double runs = static_cast<double>(state.iterations());
  state.counters["construct_ms"] = 1e3 * construct / runs;
  state.counters["improve_ms"] = 1e3 * improve / runs;
}
BENCHMARK(BM_TourThreads)->ArgName("threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(5);

// The tour's stages on the same dots, to show where the time and the quality come
// from: construction (greedy edge vs nearest neighbour), the local optimum, and
// perturbation trials per point (range(1), in tenths).
static void BM_TourStages(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const Instance& in = uniform_instance(n);
  plan::TourStats st;
  double travel = 0, cpu = 0;
  plan::TourOptions opt;
  opt.kicks = static_cast<long>(state.range(1)) * static_cast<long>(n) / 10;
  for (auto _ : state) {
    Timer t;
    travel = plan::tour_travel(in.pts, in.partner, {0, 0}, plan::plan_tour(in.pts, in.partner, {0, 0}, opt, &st));
    cpu = t.cpu_s();
  }
  plan::TourOptions built;
  built.improve = false;
  const double greedy_edge = plan::tour_travel(in.pts, in.partner, {0, 0}, plan::plan_tour(in.pts, in.partner, {0, 0}, built));
  state.counters["ratio_to_emst"] = travel / in.emst;
  state.counters["ratio_greedy_edge_to_emst"] = greedy_edge / in.emst;
  state.counters["cpu_s"] = cpu;
  state.counters["construct_wall_s"] = st.construct_seconds;
  state.counters["improve_wall_s"] = st.improve_seconds;
  state.counters["moves"] = static_cast<double>(st.moves_2opt + st.moves_oropt);
  state.counters["kicks_kept"] = static_cast<double>(st.kicks_kept);
  state.counters["reversed_per_point"] = static_cast<double>(st.reversed) / static_cast<double>(n);
}
BENCHMARK(BM_TourStages)
    ->Args({100000, 0})
    ->Args({100000, 3})
    ->Args({100000, 10})
    ->Args({1000000, 0})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// vpype's own line-sort benchmark file (7,000 random lines on 10 x 10 cm), planned as
// `stipplot export 7k_lines.svg --profile grbl-servo` does, from the plotter's home.
// Travel between strokes (target <= 4,000 mm; vpype 1.14 `linesort --two-opt`: 4,063 mm
// in 7.03 s, plain `linesort`: 5,300 mm in 1.88 s, measured in ../shared/data/README.md).
static void BM_Plan7kLines(benchmark::State& state) {
  const std::string path = std::string(STIPPLOT_SHARED_DIR) + "/data/7k_lines.svg";
  const Drawing d = read_svg(path);
  PlanOptions opt;
  opt.optimize_effort = static_cast<double>(state.range(0)) / 10;
  opt.origin = MachineTransform(find_profile("grbl-servo"), d.page).page_position_of_machine_zero();
  auto between = [](const Plan& p) {
    double s = 0;
    const Stroke* last = nullptr;
    for (const auto& l : p.layers)
      for (const auto& st : l.strokes) {
        if (last) s += std::hypot(st.pts.front().x - last->pts.back().x, st.pts.front().y - last->pts.back().y);
        last = &st;
      }
    return s;
  };
  double cpu = 0;
  const Plan p = timed_plan(state, d, opt, cpu);
  PlanOptions nn = opt;
  nn.optimize_seconds = 0;
  size_t strokes = 0;
  for (const auto& l : p.layers) strokes += l.strokes.size();
  state.counters["strokes"] = static_cast<double>(strokes);
  state.counters["between_strokes_mm"] = between(p);
  state.counters["with_home_mm"] = pen_up_travel(p, opt.origin);
  state.counters["construction_only_between_mm"] = between(plan_drawing(d, nn));
  state.counters["between_to_vpype_two_opt"] = between(p) / 4063;
  state.counters["plan_cpu_s"] = cpu;
}
BENCHMARK(BM_Plan7kLines)->Arg(0)->Arg(3)->Arg(10)->Unit(benchmark::kMillisecond)->Iterations(1);

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
  state.counters["travel_planned_to_construction_only"] = planned / greedy;
  state.counters["plot_estimate_h"] = estimate / 3600;
  state.counters["plan_to_stipple_time"] = plan_s / stipple_s;
}
BENCHMARK(BM_PlanStipple)->Arg(1530)->Unit(benchmark::kMillisecond)->Iterations(1);

// The Hubble deep field stippled as `stipplot stipple hubble_deep_field.jpg -a 1.2px -b 4px
// -o x.gcode` does (216k dots on A4), planned from the grbl-servo home: pen-up travel /
// EMST for the planner and, in the same process, the previous planner (whose 2 s
// wall-clock budget gave 1.089 on a quiet machine and 1.21-1.26 under load).
static void BM_PlanHubbleStipple(benchmark::State& state) {
  const Image img = load_image(std::string(STIPPLOT_SHARED_DIR) + "/images/hubble_deep_field.jpg");
  StippleParams sp;
  sp.a = 1.2;
  sp.b = 4;
  const Drawing d = stipple(img, sp, Placement{});
  PlanOptions opt;
  opt.origin = MachineTransform(find_profile("grbl-servo"), d.page).page_position_of_machine_zero();
  double cpu = 0;
  const Plan p = timed_plan(state, d, opt, cpu);
  std::vector<Vec2> pts;
  for (const Dot& dot : d.layers.at(0).dots) pts.push_back(dot.c);
  const std::vector<int32_t> partner(pts.size(), -1);
  const double mst = spatial::total_cost(spatial::euclidean_mst(pts));
  Timer tp;
  const double previous = plan::tour_travel(pts, partner, opt.origin,
                                            bench::previous::previous_tour(pts, partner, opt.origin, 2.0));
  state.counters["dots"] = static_cast<double>(pts.size());
  state.counters["ratio_planned_to_emst"] = pen_up_travel(p, opt.origin) / mst;
  state.counters["ratio_previous_to_emst"] = previous / mst;
  state.counters["plan_cpu_s"] = cpu;
  state.counters["previous_cpu_s"] = tp.cpu_s();
}
BENCHMARK(BM_PlanHubbleStipple)->Unit(benchmark::kMillisecond)->Iterations(1);

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

// Joining a layer's polylines through shared ends (plan::join_polylines), on the two
// shapes the methods give it: range(0) = 0, 25,000 short hatch lines of which every
// other pair meets end to end (sketch's ground); 1, one outline of 433,000 points (the
// tree's). Against BM_CopyLines, the same points copied into strokes and nothing else:
// the floor any join stands on.
std::vector<Polyline> join_input(int64_t shape) {
  Rng rng(5);
  std::vector<Polyline> lines;
  if (shape == 0) {
    for (int i = 0; i < 25000; ++i) {
      const Vec2 a{rng.uniform() * 200, rng.uniform() * 280};
      const Vec2 b{a.x + 1 + rng.uniform() * 3, a.y + rng.uniform()};
      lines.push_back({{a, b}});
      if (i % 2) lines.push_back({{b, {b.x + 2, b.y + 1}}});
    }
  } else {
    Polyline pl;
    for (int i = 0; i < 433000; ++i) pl.pts.push_back({100 + 80 * std::cos(i * 1e-4) + rng.uniform() * 0.01, 140 + 80 * std::sin(i * 1e-4)});
    lines.push_back(std::move(pl));
  }
  return lines;
}
static void BM_JoinPolylines(benchmark::State& state) {
  const std::vector<Polyline> lines = join_input(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(plan::join_polylines(lines, 0.05).data());
}
BENCHMARK(BM_JoinPolylines)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
static void BM_CopyLines(benchmark::State& state) {
  const std::vector<Polyline> lines = join_input(state.range(0));
  for (auto _ : state) {
    std::vector<Stroke> out;
    for (const Polyline& pl : lines) out.push_back({pl.pts});
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_CopyLines)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
