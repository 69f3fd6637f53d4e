// Pointillism (seed 004): a 12-megapixel photo to SVG (target: <= 3 s), with the
// baselines its speed rests on, run in the same process:
//  - equal-disc PDS on a blocked-pixel map vs brute force (every placed disc checked)
//    and vs the stippler's uniform grid of dots (pds::DotGrid);
//  - the bucketed random permutation vs a global Fisher-Yates shuffle.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "image/image.hpp"
#include "methods/pointillism/pointillism.hpp"
#include "methods/stipple/pds.hpp"
#include "svg/svg_writer.hpp"

using namespace stipplot;

namespace {

// The coffee photo scaled up to width x height (a synthetic colour field if the
// shared images are not there).
Image photo(int width, int height) {
  Image out;
  out.width = width;
  out.height = height;
  out.rgb.resize(out.pixels() * 3);
  const auto path = std::filesystem::path(__FILE__).parent_path() / "../../shared/images/coffee.png";
  cv::Mat dst(height, width, CV_8UC3, out.rgb.data());
  if (std::filesystem::exists(path)) {
    Image src = load_image(path.string());
    cv::Mat s(src.height, src.width, CV_8UC3, src.rgb.data());
    cv::resize(s, dst, dst.size(), 0, 0, cv::INTER_CUBIC);
  } else {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        uint8_t* p = &out.rgb[(static_cast<size_t>(y) * width + x) * 3];
        p[0] = static_cast<uint8_t>(128 + 120 * std::sin(x * 0.003));
        p[1] = static_cast<uint8_t>(128 + 120 * std::sin(y * 0.004 + 1));
        p[2] = static_cast<uint8_t>(128 + 120 * std::sin((x + y) * 0.002 + 2));
      }
  }
  return out;
}

void BM_Photo12MP_ToSvg(benchmark::State& state) {
  const Image img = photo(4240, 2830);  // 12.0 megapixels
  pointillism::Params p;
  Placement pl;
  size_t circles = 0, bytes = 0;
  for (auto _ : state) {
    Drawing d = pointillism::pointillism(img, p, pl);
    std::string svg = svg_string(d);
    circles = d.primitive_count();
    bytes = svg.size();
    benchmark::DoNotOptimize(svg.data());
  }
  state.counters["circles"] = static_cast<double>(circles);
  state.counters["svg_MB"] = static_cast<double>(bytes) / 1e6;
}
BENCHMARK(BM_Photo12MP_ToSvg)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_Photo12MP_Paint(benchmark::State& state) {
  const Image img = photo(4240, 2830);
  pointillism::Params p;
  for (auto _ : state) {
    auto r = pointillism::paint(img, p);
    benchmark::DoNotOptimize(r.strokes.data());
  }
}
BENCHMARK(BM_Photo12MP_Paint)->Unit(benchmark::kMillisecond)->Iterations(1);

// Ebauche PDS (r = 3, alpha = 0.5: discs 3 px apart, maximal) on a 256 x 256 image.
void BM_EbauchePds(benchmark::State& state) {
  const bool naive = state.range(0) == 1;
  const int w = 256, h = 256;
  Rng rng(7);
  const auto order = pointillism::random_order(static_cast<size_t>(w) * h, rng);
  size_t dots = 0;
  for (auto _ : state) {
    auto d = naive ? pointillism::equal_disc_pds_naive(w, h, 3.0, order) : pointillism::equal_disc_pds(w, h, 3.0, order);
    dots = d.size();
    benchmark::DoNotOptimize(d.data());
  }
  state.counters["dots"] = static_cast<double>(dots);
  state.SetLabel(naive ? "naive (all discs checked)" : "blocked-pixel map");

}
BENCHMARK(BM_EbauchePds)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The same PDS with the stippler's uniform grid of dots (pds::DotGrid) as the index.
std::vector<uint32_t> grid_pds(int width, int height, double min_dist, const std::vector<uint32_t>& order) {
  pds::DotGrid grid(width, height, min_dist);
  const double r2 = std::ceil(min_dist * min_dist - 1e-9) - 1;
  std::vector<uint32_t> dots;
  const uint32_t w = static_cast<uint32_t>(width);
  for (uint32_t idx : order) {
    const int x = static_cast<int>(idx % w), y = static_cast<int>(idx / w);
    if (!grid.any_within(x, y, min_dist, r2)) {
      grid.insert(x, y);
      dots.push_back(idx);
    }
  }
  return dots;
}

// Maximal ebauche PDS on 12 M pixels: blocked-pixel map (0) vs uniform dot grid (1).
void BM_EbauchePds12M(benchmark::State& state) {
  const bool grid = state.range(0) == 1;
  const int w = 4240, h = 2830;
  Rng rng(7);
  const auto order = pointillism::random_order(static_cast<size_t>(w) * h, rng);
  size_t dots = 0;
  for (auto _ : state) {
    auto d = grid ? grid_pds(w, h, 3.0, order) : pointillism::equal_disc_pds(w, h, 3.0, order);
    dots = d.size();
    benchmark::DoNotOptimize(d.data());
  }
  state.counters["dots"] = static_cast<double>(dots);
  state.SetLabel(grid ? "uniform dot grid" : "blocked-pixel map");
}
BENCHMARK(BM_EbauchePds12M)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(2);

// Random visiting order for 12 M pixels.
void BM_RandomOrder12M(benchmark::State& state) {
  const bool global = state.range(0) == 1;
  const size_t n = 4240 * 2830;
  for (auto _ : state) {
    Rng rng(3);
    auto o = global ? pds::random_order(n, rng) : pointillism::random_order(n, rng);
    benchmark::DoNotOptimize(o.data());
  }
  state.SetLabel(global ? "global Fisher-Yates" : "bucketed");
}
BENCHMARK(BM_RandomOrder12M)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
