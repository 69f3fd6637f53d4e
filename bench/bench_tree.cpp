// Dendritic drawings (seed 002): exact MST of stipple points from a photo, by the
// kd-tree Borůvka (mst_exact) and by the paper's O(n²) Prim on the complete graph.
//
//   BM_MstExact/<cost>/<n>     the scalable exact MST alone (targets at n=100000:
//                              ED <= 0.3 s, BD <= 0.6 s, SIBD <= 1.5 s)
//   BM_RatioVsPrim/<cost>/<n>  both algorithms on the same points in one run; counters
//                              prim_s, exact_s, ratio (target >= 20 at n=30000) and
//                              weight_match (1 if the totals agree)
//   BM_TreeMethod/<variant>    the whole method (stipples, edges, MST) on a 1024x1024 photo
//   BM_ForestTrails/<n>        the SIBD tree of n photo stipples drawn as trails (the retrace
//                              DP and Hierholzer, forest_trails) against the MST itself in the
//                              same run: counter ratio_to_mst (the trails should cost a small
//                              share of the tree), trails, retraced
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <opencv2/imgproc.hpp>

#include "image/image.hpp"
#include "methods/stipple/pds.hpp"
#include "methods/tree/trails.hpp"
#include "methods/tree/tree.hpp"

using namespace stipplot;
using namespace stipplot::tree;

namespace {

std::string photo_path() {
  return (std::filesystem::path(__FILE__).parent_path().parent_path() / "examples" / "coffee.png").string();
}

Image resized(const Image& img, int w, int h) {
  cv::Mat src(img.height, img.width, CV_8UC3, const_cast<uint8_t*>(img.rgb.data())), dst;
  cv::resize(src, dst, cv::Size(w, h), 0, 0, cv::INTER_CUBIC);
  Image out;
  out.width = w, out.height = h;
  out.rgb.assign(dst.data, dst.data + size_t(w) * h * 3);
  return out;
}

// Stipple points (a=2, b=8, grayscale order) of the photo scaled so that about
// `target` points come out; d is the slightly blurred luma, as the method uses.
const PointSet& photo_points(size_t target) {
  static std::map<size_t, PointSet> cache;
  auto it = cache.find(target);
  if (it != cache.end()) return it->second;
  const Image photo = load_image(photo_path());
  TreeParams p;
  p.variant = parse_variant("ed");
  double scale = 1;
  PointSet pts;
  for (int attempt = 0; attempt < 3; ++attempt) {
    Image img = resized(photo, int(photo.width * scale), int(photo.height * scale));
    auto grey = img.luma();
    Rng rng(1);
    auto dots = pds::sample(img.width, img.height, grey, pds::RadiusTable::linear(p.a, p.b, false),
                            pds::grayscale_order(grey, rng));
    cv::Mat g(img.height, img.width, CV_8U, grey.data()), f;
    g.convertTo(f, CV_32F);
    cv::GaussianBlur(f, f, cv::Size(0, 0), p.sigma);
    pts = PointSet{};
    for (uint32_t i : dots) {
      const int x = int(i % uint32_t(img.width)), y = int(i / uint32_t(img.width));
      pts.push(float(x), float(y), f.at<float>(y, x));
    }
    if (std::abs(double(pts.size()) - double(target)) < 0.01 * double(target)) break;
    scale *= std::sqrt(double(target) / double(pts.size()));
  }
  return cache.emplace(target, std::move(pts)).first->second;
}

CostParams cost_of(int k) {
  CostParams c;
  c.kind = k == 0 ? Distance::ED : (k == 1 ? Distance::BD : Distance::SIBD);
  c.alpha = k == 2 ? 0.5 : 1.0;
  c.h = 300;
  return c;
}

void BM_MstExact(benchmark::State& state) {
  const CostParams c = cost_of(int(state.range(0)));
  const PointSet& pts = photo_points(size_t(state.range(1)));
  MstStats st;
  for (auto _ : state) {
    auto edges = mst_exact(pts, c, &st);
    benchmark::DoNotOptimize(edges.data());
  }
  state.SetLabel(to_string(c.kind));
  state.counters["points"] = double(pts.size());
  state.counters["rounds"] = st.rounds;
  state.counters["queries_per_point"] = double(st.queries) / double(pts.size());
}
BENCHMARK(BM_MstExact)
    ->ArgsProduct({{0, 1, 2}, {30000, 100000}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

void BM_RatioVsPrim(benchmark::State& state) {
  const CostParams c = cost_of(int(state.range(0)));
  const PointSet& pts = photo_points(size_t(state.range(1)));
  double prim_s = 0, exact_s = 0, match = 0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    auto ref = mst_prim_reference(pts, c);
    auto t1 = std::chrono::steady_clock::now();
    auto fast = mst_exact(pts, c);
    auto t2 = std::chrono::steady_clock::now();
    prim_s = std::chrono::duration<double>(t1 - t0).count();
    exact_s = std::chrono::duration<double>(t2 - t1).count();
    const double a = total_cost(ref), b = total_cost(fast);
    match = (std::abs(a - b) <= 1e-9 * a && ref.size() == fast.size()) ? 1 : 0;
  }
  state.SetLabel(to_string(c.kind));
  state.counters["points"] = double(pts.size());
  state.counters["prim_s"] = prim_s;
  state.counters["exact_s"] = exact_s;
  state.counters["ratio"] = prim_s / exact_s;
  state.counters["weight_match"] = match;
}
BENCHMARK(BM_RatioVsPrim)->ArgsProduct({{0, 1, 2}, {30000}})->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_TreeMethod(benchmark::State& state) {
  static const char* names[] = {"ed", "bd", "sibd", "bd+sibd", "csibd"};
  const Image img = resized(load_image(photo_path()), 1024, 1024);
  TreeParams p;
  p.variant = parse_variant(names[state.range(0)]);
  Placement place;
  size_t segments = 0;
  for (auto _ : state) {
    Drawing d = tree_drawing(img, p, place);
    segments = d.primitive_count();
  }
  state.SetLabel(names[state.range(0)]);
  state.counters["segments"] = double(segments);
}
BENCHMARK(BM_TreeMethod)->DenseRange(0, 4)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_ForestTrails(benchmark::State& state) {
  const PointSet& pts = photo_points(size_t(state.range(0)));
  const auto t0 = std::chrono::steady_clock::now();
  const auto edges = mst_exact(pts, cost_of(2));
  const double mst_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<Vec2> pos;
  for (size_t i = 0; i < pts.size(); ++i) pos.push_back({0.3 * pts.x[i], 0.3 * pts.y[i]});  // a pen-width grid, in mm
  std::vector<TrailEdge> te;
  for (const Edge& e : edges) te.push_back({e.a, e.b});
  TrailPlan plan;
  double trails_s = 0;
  for (auto _ : state) {
    const auto t1 = std::chrono::steady_clock::now();
    plan = forest_trails(pos, te, 12.5);
    trails_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    benchmark::DoNotOptimize(plan.trails.data());
  }
  state.counters["points"] = double(pts.size());
  state.counters["trails"] = double(plan.trails.size());
  state.counters["retraced"] = double(plan.retraced_edges);
  state.counters["ratio_to_mst"] = trails_s / mst_s;
}
BENCHMARK(BM_ForestTrails)->Arg(100000)->Unit(benchmark::kMillisecond)->Iterations(3);

// The loops two pens wide (--weight 2) against the single-line trails of the same tree, in
// one process: the ratio is the figure (O((V + E log degree) 4) against the trails' O(V + E)).
void BM_ForestOutlines(benchmark::State& state) {
  const PointSet& pts = photo_points(size_t(state.range(0)));
  const auto edges = mst_exact(pts, cost_of(0));
  std::vector<Vec2> pos;
  for (size_t i = 0; i < pts.size(); ++i) pos.push_back({0.3 * pts.x[i], 0.3 * pts.y[i]});
  std::vector<TrailEdge> te;
  for (const Edge& e : edges) te.push_back({e.a, e.b});
  const auto t0 = std::chrono::steady_clock::now();
  benchmark::DoNotOptimize(forest_trails(pos, te, 12.5).trails.data());
  const double trails_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<Polyline> loops;
  double loops_s = 0;
  for (auto _ : state) {
    const auto t1 = std::chrono::steady_clock::now();
    loops = forest_outlines(pos, te, 0.15);
    loops_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    benchmark::DoNotOptimize(loops.data());
  }
  size_t points = 0;
  for (const auto& l : loops) points += l.pts.size();
  state.counters["loops"] = double(loops.size());
  state.counters["loop_points"] = double(points);
  state.counters["ratio_to_trails"] = loops_s / trails_s;
}
BENCHMARK(BM_ForestOutlines)->Arg(100000)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
