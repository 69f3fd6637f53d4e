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
  // Also, for each (one-thread run, its serial part), the most two threads could give it:
  // Amdahl's T1 / (S + (T1 - S) / 2), were all but the serial part halved.
  void add_ceilings(std::vector<std::pair<std::string, std::string>> c) { ceilings_ = std::move(c); }
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs)
      if (r.run_type == Run::RT_Iteration || r.aggregate_name == "median") {
        std::string name = r.run_name.function_name + (r.run_name.args.empty() ? "" : "/" + r.run_name.args);
        // CPU time: single-threaded code, robust to a loaded machine; real time where the
        // benchmark asks for it (parallel code, whose CPU time is the sum of its threads').
        times_[name] = r.run_name.time_type == "real_time" ? r.GetAdjustedRealTime() : r.GetAdjustedCPUTime();
        real_[name] = r.run_name.time_type == "real_time";
        unit_[name] = benchmark::GetTimeUnitString(r.time_unit);
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
    for (const auto& [one, serial] : ceilings_) {
      auto t = times_.find(one), sp = times_.find(serial);
      if (t != times_.end() && sp != times_.end() && t->second > sp->second)
        std::printf("CEILING %s on 2 threads with %s serial (%.0f%% of it): %.2fx at most\n", one.c_str(), serial.c_str(),
                    100 * sp->second / t->second, t->second / (sp->second + (t->second - sp->second) / 2));
    }
    // What stays serial, as the one-thread run would have it were all the rest halved:
    // T2 = S + (T1 - S) / 2 gives S = 2 T2 - T1; of it the decode, and the rest (what a
    // further parallel part could take).
    for (const auto& [one, serial] : ceilings_)
      for (const auto& [two, base] : pairs_) {
        auto t1 = times_.find(one), t2 = times_.find(two), sp = times_.find(serial);
        if (base != one || t1 == times_.end() || t2 == times_.end() || sp == times_.end()) continue;
        const double s = 2 * t2->second - t1->second;
        const char* u = unit_[one].c_str();
        std::printf("SERIAL %s: 2 x T2 - T1 = %.0f %s as if serial, %s %.0f %s of it, the rest %.0f %s\n", two.c_str(), s,
                    u, serial.c_str(), sp->second, u, s - sp->second, u);
      }
  }

 private:
  std::vector<std::pair<std::string, std::string>> pairs_, ceilings_;
  std::map<std::string, double> times_;
  std::map<std::string, std::string> unit_;
  std::map<std::string, bool> real_;
};

// What a benchmark's main() does: run them all, then the ratios of the pairs.
inline int run_benchmarks(int argc, char** argv, std::vector<std::pair<std::string, std::string>> pairs,
                          std::vector<std::pair<std::string, std::string>> ceilings = {}) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter rep(std::move(pairs));
  rep.add_ceilings(std::move(ceilings));
  benchmark::RunSpecifiedBenchmarks(&rep);
  benchmark::Shutdown();
  return 0;
}

}  // namespace stipplot::bench

#define STIPPLOT_BENCH_MAIN(...) \
  int main(int argc, char** argv) { \
    return stipplot::bench::run_benchmarks(argc, argv, std::vector<std::pair<std::string, std::string>> __VA_ARGS__); \
  }
