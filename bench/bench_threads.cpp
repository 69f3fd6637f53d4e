// Whole method commands (stipple, tree, sketch, pointillism) on a 12-megapixel photo (coffee.png upscaled), each with its
// plot-time budget search (the default --time 1h), run in this process with --threads 1
// (the baseline) and --threads 2: wall-clock time, so the ratio is the speed-up the
// parallel parts give (util/threads.hpp). The output is the same bit for bit for both
// (tests "[threads]"). Run on a quiet machine: a busy core takes the second thread's time.
//   ./build/bench/bench_threads
#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "photo_12mp.hpp"
#include "ratio_reporter.hpp"
#include "run_command.hpp"

namespace {

namespace fs = std::filesystem;

void whole_command(benchmark::State& state, const char* method) {
  const std::string out = (fs::temp_directory_path() / (std::string("stipplot_bench_threads_") + method + ".svg")).string();
  const std::vector<std::string> args = {method, stipplot::bench::photo_12mp(), "-o", out, "-q", "--threads",
                                         std::to_string(state.range(0))};
  // Once untimed: the first run in a process pays for the heap's pages, which every later
  // run reuses; without it the count run first (1) would carry that cost alone.
  bench_cli::run_command(args, "threads");
  for (auto _ : state) benchmark::DoNotOptimize(bench_cli::run_command(args, "threads"));
}
void BM_Stipple(benchmark::State& s) { whole_command(s, "stipple"); }
void BM_Tree(benchmark::State& s) { whole_command(s, "tree"); }
void BM_Sketch(benchmark::State& s) { whole_command(s, "sketch"); }
void BM_Pointillism(benchmark::State& s) { whole_command(s, "pointillism"); }

}  // namespace

BENCHMARK(BM_Stipple)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Tree)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Sketch)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Pointillism)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);

STIPPLOT_BENCH_MAIN_AS_CLI({{"BM_Stipple/2", "BM_Stipple/1"},
                            {"BM_Tree/2", "BM_Tree/1"},
                            {"BM_Sketch/2", "BM_Sketch/1"},
                            {"BM_Pointillism/2", "BM_Pointillism/1"}})
