// Grayscale-order PDS on a 3840x2160 photo-like image (a=2, b=8) against a literal
// reference implementation: std::sort of (f, pixel) pairs and a scan of every pixel
// of the disc in an occupancy bitmap; the Lloyd relaxation of its dots on 1 and 2
// threads. Run: ./build/bench/bench_stipple
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "methods/stipple/pds.hpp"
#include "methods/stipple/stipple.hpp"
#include "ratio_reporter.hpp"
#include "synthetic.hpp"
#include "util/threads.hpp"

namespace {

using namespace stipplot;

constexpr int W = 3840, H = 2160;
constexpr double A = 2, B = 8;

const std::vector<uint8_t>& image() {
  static const std::vector<uint8_t> img = bench::photo_like_grey(W, H);
  return img;
}

// The literal reading of the paper: sort by f = d + u, then for each pixel scan every
// pixel of its disc for an existing dot. O(n log n + n r^2).
std::vector<uint32_t> reference_pds(const std::vector<uint8_t>& d, uint64_t seed) {
  Rng rng(seed);
  std::vector<std::pair<double, uint32_t>> f(d.size());
  for (uint32_t i = 0; i < d.size(); ++i) f[i] = {d[i] + rng.uniform(), i};
  std::sort(f.begin(), f.end());
  std::vector<uint8_t> occ(d.size(), 0);
  std::vector<uint32_t> dots;
  for (const auto& [key, idx] : f) {
    int x = static_cast<int>(idx % W), y = static_cast<int>(idx / W);
    double r = A + B * d[idx] / 255.0, r2 = r * r;
    int ri = static_cast<int>(r);
    bool blocked = false;
    for (int dy = -ri; dy <= ri && !blocked; ++dy) {
      int yy = y + dy;
      if (yy < 0 || yy >= H) continue;
      for (int dx = -ri; dx <= ri; ++dx) {
        int xx = x + dx;
        if (xx < 0 || xx >= W || dx * dx + dy * dy > r2) continue;
        if (occ[static_cast<size_t>(yy) * W + xx]) {
          blocked = true;
          break;
        }
      }
    }
    if (!blocked) {
      occ[idx] = 1;
      dots.push_back(idx);
    }
  }
  return dots;
}

void BM_GrayscalePDS(benchmark::State& state) {
  const auto& d = image();
  auto radius = pds::RadiusTable::linear(A, B, false);
  size_t dots = 0;
  for (auto _ : state) {
    Rng rng(1);
    auto order = pds::grayscale_order(d, rng);
    auto out = pds::sample(W, H, d, radius, order);
    dots = out.size();
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["dots"] = static_cast<double>(dots);
  state.counters["Mpixel/s"] = benchmark::Counter(static_cast<double>(d.size()) * state.iterations() / 1e6,
                                                  benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GrayscalePDS)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_ReferencePDS(benchmark::State& state) {
  const auto& d = image();
  size_t dots = 0;
  for (auto _ : state) {
    auto out = reference_pds(d, 1);
    dots = out.size();
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["dots"] = static_cast<double>(dots);
}
BENCHMARK(BM_ReferencePDS)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// The two halves of the fast method, to see where time goes: the order alone, on 1 and
// 2 threads (range(0); the same order on both). Real time: the second thread's work is
// not the caller's.
void BM_GrayscaleOrderOnly(benchmark::State& state) {
  const auto& d = image();
  set_thread_count(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    Rng rng(1);
    auto order = pds::grayscale_order(d, rng);
    benchmark::DoNotOptimize(order.data());
  }
  set_thread_count(0);
}
BENCHMARK(BM_GrayscaleOrderOnly)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_StippleVariant(benchmark::State& state) {
  static const Image img = Image::from_grey(W, H, image());
  StippleParams p;
  p.method = static_cast<StippleMethod>(state.range(0));
  p.a = A;
  p.b = B;
  p.a_b = p.a_w = A;
  p.b_b = p.b_w = B;
  for (auto _ : state) {
    auto r = stipple_pixels(img, p);
    benchmark::DoNotOptimize(r.layers.data());
  }
  state.SetLabel(to_string(p.method));
}
BENCHMARK(BM_StippleVariant)->DenseRange(0, 5)->Unit(benchmark::kMillisecond);

// Lloyd relaxation (relax_points, 6 iterations as the tone law's default) of the
// grayscale-order dots of the photo, on 1 and 2 threads (range(0)); its floor, the same
// iterations of one pass reading every cell's weight. Real time: the second thread's
// work is not the caller's.
const std::vector<Vec2>& relax_start() {
  static const std::vector<Vec2> pts = [] {
    Rng rng(1);
    const auto radius = pds::RadiusTable::linear(A, B, false);
    std::vector<Vec2> p;
    for (uint32_t idx : pds::sample(W, H, image(), radius, pds::grayscale_order(image(), rng)))
      p.push_back({idx % W + 0.5, idx / W + 0.5});
    return p;
  }();
  return pts;
}
constexpr int kRelaxIterations = 6;

void BM_Relax(benchmark::State& state) {
  const auto radius = pds::RadiusTable::linear(A, B, false);
  set_thread_count(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    std::vector<Vec2> pts = relax_start();
    relax_points(pts, image(), radius, W, H, kRelaxIterations);
    benchmark::DoNotOptimize(pts.data());
  }
  set_thread_count(0);
  state.counters["dots"] = static_cast<double>(relax_start().size());
}
BENCHMARK(BM_Relax)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_RelaxCellPass(benchmark::State& state) {
  const auto radius = pds::RadiusTable::linear(A, B, false);
  std::array<double, 256> weight{};
  for (int v = 0; v < 256; ++v) weight[static_cast<size_t>(v)] = 1 / std::pow(radius.r[v], 4);
  for (auto _ : state) {
    double sum = 0;
    for (int it = 0; it < kRelaxIterations; ++it)
      for (uint8_t v : image()) sum += weight[v];
    benchmark::DoNotOptimize(sum);
  }
}
BENCHMARK(BM_RelaxCellPass)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

STIPPLOT_BENCH_MAIN({{"BM_GrayscalePDS", "BM_ReferencePDS"},
                     {"BM_Relax/1", "BM_RelaxCellPass"},
                     {"BM_Relax/2", "BM_Relax/1"},
                     {"BM_GrayscaleOrderOnly/2", "BM_GrayscaleOrderOnly/1"}})
