// Whole method commands (stipple, tree, sketch, pointillism) on a 12-megapixel photo (coffee.png upscaled), as a PNG
// (argument 0) and as a JPEG (1), each with its plot-time budget search (the default
// --time 1h), run in this process with --threads 1 (the baseline) and --threads 2:
// wall-clock time, so the ratio is the speed-up the parallel parts give
// (util/threads.hpp). The output is the same bit for bit for both (tests "[threads]").
// The photo's decoding is timed alone too: no thread shortens it, so each command's
// CEILING line is the most two threads could give it (Amdahl), and its SERIAL line what
// of it stays serial as measured (2 T2 - T1: the decode, and the rest that a further
// parallel part could take). Run on a quiet machine: a busy core takes the second
// thread's time.
//   ./build/bench/bench_threads
// The Paired benchmarks run each command on 1 and 2 threads in turns and report the
// median of the pairs' ratios (counter speedup), robust to the VM's drift.
#include <stb_image.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "photo_12mp.hpp"
#include "ratio_reporter.hpp"
#include "run_command.hpp"

namespace {

namespace fs = std::filesystem;

const std::string& photo(int64_t jpeg) { return jpeg ? stipplot::bench::photo_12mp_jpeg() : stipplot::bench::photo_12mp(); }

// The command line of `method` on the photo (0 = PNG, 1 = JPEG) with `threads` threads.
std::vector<std::string> command(const char* method, int64_t jpeg, int64_t threads) {
  const std::string out = (fs::temp_directory_path() / (std::string("stipplot_bench_threads_") + method + ".svg")).string();
  return {method, photo(jpeg), "-o", out, "-q", "--threads", std::to_string(threads)};
}

// Arguments: threads, and the photo (0 = PNG, 1 = JPEG).
void whole_command(benchmark::State& state, const char* method) {
  const std::vector<std::string> args = command(method, state.range(1), state.range(0));
  // Once untimed: the first run in a process pays for the heap's pages, which every later
  // run reuses; without it the count run first (1) would carry that cost alone.
  bench_cli::run_command(args, "threads");
  for (auto _ : state) benchmark::DoNotOptimize(bench_cli::run_command(args, "threads"));
}
// The same command on 1 and 2 threads in turns (1 then 2, then 2 then 1, ...), each pair
// timed back to back: this VM's pace drifts by a third over seconds, which the
// separate runs above take whole but a pair shares. The speed-up is the median of the
// pairs' ratios; t1 and t2 the medians of each count's times. Argument: the photo.
void paired_command(benchmark::State& state, const char* method) {
  auto args = [&](int threads) { return command(method, state.range(0), threads); };
  bench_cli::run_command(args(2), "threads");  // the heap's pages, as above
  std::vector<double> t1, t2, ratio;
  auto timed = [&](int threads) {
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(bench_cli::run_command(args(threads), "threads"));
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  for (auto _ : state) {
    const bool one_first = t1.size() % 2 == 0;
    const double a = timed(one_first ? 1 : 2), b = timed(one_first ? 2 : 1);
    t1.push_back(one_first ? a : b);
    t2.push_back(one_first ? b : a);
    ratio.push_back(t1.back() / t2.back());
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
  };
  state.counters["t1_ms"] = median(t1);
  state.counters["t2_ms"] = median(t2);
  state.counters["speedup"] = median(ratio);
  state.counters["speedup_min"] = *std::min_element(ratio.begin(), ratio.end());
}
void BM_StipplePaired(benchmark::State& s) { paired_command(s, "stipple"); }
void BM_TreePaired(benchmark::State& s) { paired_command(s, "tree"); }
void BM_SketchPaired(benchmark::State& s) { paired_command(s, "sketch"); }
void BM_PointillismPaired(benchmark::State& s) { paired_command(s, "pointillism"); }

void BM_Stipple(benchmark::State& s) { whole_command(s, "stipple"); }
void BM_Tree(benchmark::State& s) { whole_command(s, "tree"); }
void BM_Sketch(benchmark::State& s) { whole_command(s, "sketch"); }
void BM_Pointillism(benchmark::State& s) { whole_command(s, "pointillism"); }

// The photo's decoding alone (libpng, libjpeg-turbo: one thread, as every decoder of these
// formats; only the output's first touch is spread), the part of each command no thread
// count shortens.
void BM_Decode(benchmark::State& state) {
  const std::string& path = photo(state.range(0));
  benchmark::DoNotOptimize(stipplot::load_image(path).rgb.data());
  for (auto _ : state) benchmark::DoNotOptimize(stipplot::load_image(path).rgb.data());
}

// The same photo's bytes decoded by stb_image, which read photos before libpng and
// libjpeg-turbo (the baseline of BM_Decode: the same pixels for a PNG, within 3 levels for
// a JPEG), into its own fresh buffer as stipplot did.
void BM_DecodeStb(benchmark::State& state) {
  std::ifstream in(photo(state.range(0)), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto once = [&] {
    int w = 0, h = 0, comp = 0;
    unsigned char* p = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()),
                                             static_cast<int>(bytes.size()), &w, &h, &comp, 3);
    if (!p) state.SkipWithError("stb_image failed");
    benchmark::DoNotOptimize(p);
    stbi_image_free(p);
  };
  once();
  for (auto _ : state) once();
}

}  // namespace

BENCHMARK(BM_DecodeStb)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Decode)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Stipple)->ArgsProduct({{1, 2}, {0, 1}})->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Tree)->ArgsProduct({{1, 2}, {0, 1}})->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Sketch)->ArgsProduct({{1, 2}, {0, 1}})->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Pointillism)->ArgsProduct({{1, 2}, {0, 1}})->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_StipplePaired)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(6);
BENCHMARK(BM_TreePaired)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(6);
BENCHMARK(BM_SketchPaired)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(6);
BENCHMARK(BM_PointillismPaired)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(6);

int main(int argc, char** argv) {
  stipplot::rerun_on_huge_pages(argv);
  std::vector<std::pair<std::string, std::string>> pairs = {{"BM_Decode/0", "BM_DecodeStb/0"},
                                                            {"BM_Decode/1", "BM_DecodeStb/1"}},
                                                   ceilings;
  for (const char* m : {"BM_Stipple", "BM_Tree", "BM_Sketch", "BM_Pointillism"})
    for (const char* photo : {"0", "1"}) {
      const std::string one = std::string(m) + "/1/" + photo;
      pairs.push_back({std::string(m) + "/2/" + photo, one});
      ceilings.push_back({one, std::string("BM_Decode/") + photo});
    }
  return stipplot::bench::run_benchmarks(argc, argv, pairs, ceilings);
}
