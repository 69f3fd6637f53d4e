#pragma once
// Google Benchmark's console output plus ratios between named benchmarks of the same
// run, so a speed figure is always quoted against its baseline measured in the same
// process on the same machine state. Use STIPPLOT_BENCH_MAIN({{"fast", "baseline"}, ...}).
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace stipplot::bench {

class RatioReporter : public benchmark::ConsoleReporter {
 public:
  explicit RatioReporter(std::vector<std::pair<std::string, std::string>> pairs)
      : ConsoleReporter(isatty(STDOUT_FILENO) ? OO_Defaults : OO_Tabular), pairs_(std::move(pairs)) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs)
      if (r.run_type == Run::RT_Iteration || r.aggregate_name == "median") {
        std::string name = r.run_name.function_name + (r.run_name.args.empty() ? "" : "/" + r.run_name.args);
        // CPU time: single-threaded code, robust to a loaded machine; real time where the
        // benchmark asks for it (parallel code, whose CPU time is the sum of its threads').
        times_[name] = r.run_name.time_type == "real_time" ? r.GetAdjustedRealTime() : r.GetAdjustedCPUTime();
        real_[name] = r.run_name.time_type == "real_time";
      }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    for (const auto& [fast, base] : pairs_) {
      auto f = times_.find(fast), b = times_.find(base);
      if (f != times_.end() && b != times_.end() && f->second > 0)
        std::printf("RATIO (%s time) %s vs %s: %.2fx faster\n", real_[fast] ? "real" : "CPU", fast.c_str(),
                    base.c_str(), b->second / f->second);
    }
  }

 private:
  std::vector<std::pair<std::string, std::string>> pairs_;
  std::map<std::string, double> times_;
  std::map<std::string, bool> real_;
};

// What a benchmark's main() does: run them all, then the ratios of the pairs.
inline int run_benchmarks(int argc, char** argv, std::vector<std::pair<std::string, std::string>> pairs) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter rep(std::move(pairs));
  benchmark::RunSpecifiedBenchmarks(&rep);
  benchmark::Shutdown();
  return 0;
}

}  // namespace stipplot::bench

#define STIPPLOT_BENCH_MAIN(...) \
  int main(int argc, char** argv) { \
    return stipplot::bench::run_benchmarks(argc, argv, std::vector<std::pair<std::string, std::string>> __VA_ARGS__); \
  }
