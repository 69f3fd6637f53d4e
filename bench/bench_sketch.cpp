// Colour sketch (seed 001). Run: ./build/bench/bench_sketch
//  - BM_SketchPhotoToSvg: a 12-megapixel photo (coffee.png upscaled to 4243x2828, as a
//    PNG file) loaded, sketched in RGB mode with the 8 pens, written as SVG; against the
//    same pipeline with independent random draws (BM_SketchPhotoToSvg_RandomDraws).
//  - The m solve (Newton from below) against plain bisection, and the LDS placement
//    (guide tables) against independent draws with binary search, at growing grid
//    sizes: the per-cell time stays flat (linear in cells).
//  - BM_SketchLink: one black pen's strokes of that photo on A4 (about 58k marks) linked
//    into scribbles (the planner's tour over their ends, then the link tests), against
//    the sketch that made them (BM_SketchBlack: probabilities, points, strokes).
//  - BM_SketchGround: the hatched ground of that photo on A4 with the 8 rgb pens (the
//    cells' nearest pens, then each pen's fields hatched at coverage 0.5), against the rgb
//    sketch of it (BM_SketchRgb).
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "methods/sketch/link.hpp"
#include "methods/sketch/redistribution.hpp"
#include "methods/sketch/sketch.hpp"
#include "photo_12mp.hpp"
#include "preview/preview.hpp"
#include "ratio_reporter.hpp"
#include "svg/svg_writer.hpp"
#include "util/rng.hpp"

namespace {

using namespace stipplot;
namespace fs = std::filesystem;

using bench::photo_12mp;

void photo_to_svg(benchmark::State& state, sketch::SketchParams::Sampler sampler) {
  const std::string in = photo_12mp();
  const std::string out = (fs::temp_directory_path() / "stipplot_bench_sketch.svg").string();
  sketch::SketchParams p;
  p.sampler = sampler;
  Placement pl;
  pl.landscape = true;
  size_t strokes = 0;
  for (auto _ : state) {
    Image img = load_image(in);
    Drawing d = sketch::sketch(img, p, pl);
    write_svg(d, out);
    strokes = d.primitive_count();
  }
  state.counters["strokes"] = static_cast<double>(strokes);
  fs::remove(out);
}
void BM_SketchPhotoToSvg(benchmark::State& state) { photo_to_svg(state, sketch::SketchParams::Sampler::LowDiscrepancy); }
void BM_SketchPhotoToSvg_RandomDraws(benchmark::State& state) { photo_to_svg(state, sketch::SketchParams::Sampler::Random); }
BENCHMARK(BM_SketchPhotoToSvg)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_SketchPhotoToSvg_RandomDraws)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

sketch::SketchParams black_pen() {
  sketch::SketchParams p;
  p.space = sketch::ColorSpace::Pens;
  p.pens = {Pen{"black", colors::black, 0.3}};
  return p;
}
Placement a4_landscape() {
  Placement pl;
  pl.landscape = true;
  return pl;
}
void BM_SketchBlack(benchmark::State& state) {
  const Image img = load_image(photo_12mp());
  size_t strokes = 0;
  for (auto _ : state) {
    const sketch::SketchResult r = sketch::sketch_strokes(img, black_pen(), a4_landscape());
    strokes = r.plotted_strokes();
    benchmark::DoNotOptimize(strokes);
  }
  state.counters["strokes"] = static_cast<double>(strokes);
}
void BM_SketchLink(benchmark::State& state) {
  const Image img = load_image(photo_12mp());
  const sketch::SketchResult r = sketch::sketch_strokes(img, black_pen(), a4_landscape());
  const Drawing d = sketch::to_drawing(r);
  sketch::LinkStats st;
  for (auto _ : state) {
    const Drawing linked = sketch::link_strokes(r, d, 1.0, sketch::LinkParams{}, &st);
    benchmark::DoNotOptimize(linked.layers.data());
  }
  state.counters["strokes"] = static_cast<double>(st.strokes);
  state.counters["lines"] = static_cast<double>(st.lines);
}
BENCHMARK(BM_SketchBlack)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_SketchLink)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

void BM_SketchRgb(benchmark::State& state) {
  const Image img = load_image(photo_12mp());
  for (auto _ : state) {
    const sketch::SketchResult r = sketch::sketch_strokes(img, sketch::SketchParams{}, a4_landscape());
    benchmark::DoNotOptimize(r.pens.data());
  }
}
void BM_SketchGround(benchmark::State& state) {
  const Image img = load_image(photo_12mp());
  const sketch::SketchResult r = sketch::sketch_strokes(img, sketch::SketchParams{}, a4_landscape());
  std::vector<Pen> pens;
  for (const auto& ps : r.pens) pens.push_back(ps.pen);
  size_t lines = 0;
  for (auto _ : state) {
    const hatch::PenGrid g = sketch::ground_grid(img, pens, a4_landscape());
    const Drawing d = sketch::ground_drawing(g, pens, a4_landscape(), 0.5);
    lines = d.primitive_count();
    benchmark::DoNotOptimize(lines);
  }
  state.counters["lines"] = static_cast<double>(lines);
}
BENCHMARK(BM_SketchRgb)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_SketchGround)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// A smooth probability field with zeros, like one pen of a photo.
std::vector<float> field(int side) {
  std::vector<float> p(static_cast<size_t>(side) * side);
  Rng rng(5);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      double v = 0.5 + 0.45 * std::sin(x * 12.0 / side) * std::cos(y * 9.0 / side) + 0.05 * rng.uniform();
      p[static_cast<size_t>(y) * side + x] = static_cast<float>(v < 0.35 ? 0.0 : v);
    }
  return p;
}

template <bool Naive>
void solve(benchmark::State& state) {
  const auto p = field(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto pc = Naive ? sketch::solve_point_count_bisection(p) : sketch::solve_point_count(p);
    benchmark::DoNotOptimize(pc.m);
  }
  state.SetComplexityN(static_cast<int64_t>(p.size()));
  state.counters["ns/cell"] = benchmark::Counter(static_cast<double>(p.size()) * state.iterations(),
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
void BM_SolveM(benchmark::State& s) { solve<false>(s); }
void BM_SolveM_Bisection(benchmark::State& s) { solve<true>(s); }
BENCHMARK(BM_SolveM)->RangeMultiplier(2)->Range(256, 2048)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);
BENCHMARK(BM_SolveM_Bisection)->RangeMultiplier(2)->Range(256, 2048)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);

template <bool Random>
void place(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  const auto p = field(side);
  const auto pc = sketch::solve_point_count(p);
  const auto q = sketch::densities(p, pc);
  const size_t m = static_cast<size_t>(pc.m);
  for (auto _ : state) {
    auto pts = Random ? sketch::place_points_random(q, side, side, m, 1) : sketch::place_points(q, side, side, m, 1);
    benchmark::DoNotOptimize(pts.data());
  }
  state.SetComplexityN(static_cast<int64_t>(p.size()));
  state.counters["points"] = static_cast<double>(m);
  state.counters["ns/cell"] = benchmark::Counter(static_cast<double>(p.size()) * state.iterations(),
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
void BM_PlacePoints(benchmark::State& s) { place<false>(s); }
void BM_PlacePoints_RandomBinarySearch(benchmark::State& s) { place<true>(s); }
BENCHMARK(BM_PlacePoints)->RangeMultiplier(2)->Range(256, 2048)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);
BENCHMARK(BM_PlacePoints_RandomBinarySearch)->RangeMultiplier(2)->Range(256, 2048)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);

}  // namespace

STIPPLOT_BENCH_MAIN({{"BM_SketchPhotoToSvg", "BM_SketchPhotoToSvg_RandomDraws"},
                     {"BM_SketchLink", "BM_SketchBlack"},
                     {"BM_SketchGround", "BM_SketchRgb"},
                     {"BM_SolveM/2048", "BM_SolveM_Bisection/2048"},
                     {"BM_PlacePoints/2048", "BM_PlacePoints_RandomBinarySearch/2048"}})
