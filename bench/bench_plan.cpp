// Planner benchmarks (issue 3).
#include <benchmark/benchmark.h>

#include "plan/emst.hpp"
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
}  // namespace

// 100,000 uniform random dots: planned travel / EMST weight (the quality bar, <= 1.20),
// with greedy nearest neighbour alone and generation order as baselines in the same run.
static void BM_TourUniform(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const double side = 200;
  auto pts = uniform_dots(n, side, 42);
  std::vector<int32_t> partner(n, -1);
  const double mst = plan::total_length(plan::euclidean_mst(pts));
  std::vector<uint32_t> ident(n);
  for (uint32_t i = 0; i < n; ++i) ident[i] = i;
  const double random_order = plan::tour_travel(pts, partner, {0, 0}, ident);
  plan::TourOptions nn_only;
  nn_only.seconds = 0;
  const double greedy = plan::tour_travel(pts, partner, {0, 0}, plan::plan_tour(pts, partner, {0, 0}, nn_only));
  double planned = 0;
  plan::TourStats st;
  for (auto _ : state) {
    plan::TourOptions opt;
    opt.seconds = static_cast<double>(state.range(1));
    opt.neighbors = static_cast<int>(state.range(2));
    auto order = plan::plan_tour(pts, partner, {0, 0}, opt, &st);
    planned = plan::tour_travel(pts, partner, {0, 0}, order);
  }
  state.counters["ratio_planned"] = planned / mst;
  state.counters["ratio_greedy_nn"] = greedy / mst;
  state.counters["ratio_generation_order"] = random_order / mst;
  state.counters["construct_s"] = st.construct_seconds;
  state.counters["improve_s"] = st.improve_seconds;
  state.counters["moves_2opt"] = static_cast<double>(st.moves_2opt);
  state.counters["moves_oropt"] = static_cast<double>(st.moves_oropt);
  state.counters["budget_hit"] = st.budget_hit;
}
BENCHMARK(BM_TourUniform)->Args({100000, 30, 6})->Args({100000, 30, 10})->Args({100000, 30, 14})->Unit(benchmark::kMillisecond)->Iterations(1);

BENCHMARK_MAIN();
