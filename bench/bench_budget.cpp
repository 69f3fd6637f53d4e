// Choosing a method's density for a --time budget against one run of the method at the
// density chosen. Run: ./build/bench/bench_budget
//  - BM_StippleSearch: `stipplot stipple coffee.png -o x.svg --time 1h` in process (the
//    statistics, the pilot that fits the tone curves, the search's runs, the plan and the
//    SVG); BM_StippleOneRun: the same command drawing once at the knob the search chose
//    (--knob), with the same plan and SVG. Likewise for sketch (one full run, then the
//    thinning) and tree (one full run, then one a spacing tried). The target is <= 2x
//    (issue 21: <= 3x).
//  - BM_PointillismMaxPens: `pointillism coffee.png --pens fineliner12.toml --max-pens 4`
//    (the pen search on its small copy, then the drawing); BM_PointillismChosenPens: the
//    same command given only the four pens chosen, no search. Likewise for sketch, whose
//    search draws one small sketch a set. The target is <= 2x.
#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/commands.hpp"
#include "methods/palette.hpp"
#include "ratio_reporter.hpp"
#include "run_command.hpp"

namespace {

namespace fs = std::filesystem;

std::string example(const char* name) {
  return (fs::path(__FILE__).parent_path().parent_path() / "examples" / name).string();
}

std::string run_command(const std::vector<std::string>& args) { return bench_cli::run_command(args, "budget"); }

std::vector<std::string> command(const char* method) {
  const std::string svg = (fs::temp_directory_path() / "stipplot_bench_budget.svg").string();
  std::vector<std::string> args{method, example("coffee.png"), "-o", svg, "--time", "1h", "--json"};
  // The dot stipple's search (the connected one has its own: bench_connect).
  if (std::string(method) == "stipple") args.push_back("--dots");
  return args;
}

double chosen_knob(const char* method) {
  return nlohmann::json::parse(run_command(command(method)))["budget"]["knob"].get<double>();
}

void search(benchmark::State& state, const char* method) {
  for (auto _ : state) benchmark::DoNotOptimize(run_command(command(method)));
}
void one_run(benchmark::State& state, const char* method) {
  auto args = command(method);
  const double k = chosen_knob(method);
  args.push_back("--knob");
  args.push_back(std::to_string(k));
  for (auto _ : state) benchmark::DoNotOptimize(run_command(args));
  state.counters["knob"] = k;
}

void BM_StippleSearch(benchmark::State& s) { search(s, "stipple"); }
void BM_StippleOneRun(benchmark::State& s) { one_run(s, "stipple"); }
void BM_TreeSearch(benchmark::State& s) { search(s, "tree"); }
void BM_TreeOneRun(benchmark::State& s) { one_run(s, "tree"); }
void BM_SketchSearch(benchmark::State& s) { search(s, "sketch"); }
void BM_SketchOneRun(benchmark::State& s) { one_run(s, "sketch"); }
// --max-pens 4 of the twelve fineliners, and the same command with only the pens it chose.
std::vector<std::string> max_pens_command(const char* method) {
  auto args = command(method);
  args.insert(args.end(), {"--pens", example("pens/fineliner12.toml"), "--max-pens", "4"});
  return args;
}
std::vector<std::string> chosen_pens_command(const char* method) {
  const auto chosen = nlohmann::json::parse(run_command(max_pens_command(method)))["max_pens"]["pens"];
  const std::string toml = (fs::temp_directory_path() / (std::string("stipplot_bench_chosen_") + method + ".toml")).string();
  std::ofstream f(toml);
  for (const stipplot::Pen& p : stipplot::load_palette(example("pens/fineliner12.toml")).pens)
    for (const auto& name : chosen)
      if (name.get<std::string>() == p.name)
        f << "[[pen]]\nname = \"" << p.name << "\"\ncolor = \"" << p.color.hex() << "\"\nwidth = " << p.width_mm << "\n";
  f.close();
  auto args = command(method);
  args.insert(args.end(), {"--pens", toml});
  return args;
}
void max_pens(benchmark::State& state, const char* method) {
  const auto args = max_pens_command(method);
  for (auto _ : state) benchmark::DoNotOptimize(run_command(args));
}
void chosen_pens(benchmark::State& state, const char* method) {
  const auto args = chosen_pens_command(method);
  for (auto _ : state) benchmark::DoNotOptimize(run_command(args));
}
void BM_PointillismMaxPens(benchmark::State& s) { max_pens(s, "pointillism"); }
void BM_PointillismChosenPens(benchmark::State& s) { chosen_pens(s, "pointillism"); }
void BM_SketchMaxPens(benchmark::State& s) { max_pens(s, "sketch"); }
void BM_SketchChosenPens(benchmark::State& s) { chosen_pens(s, "sketch"); }

BENCHMARK(BM_StippleSearch)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_StippleOneRun)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_TreeSearch)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_TreeOneRun)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_SketchSearch)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_SketchOneRun)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_PointillismMaxPens)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_PointillismChosenPens)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_SketchMaxPens)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_SketchChosenPens)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

STIPPLOT_BENCH_MAIN({{"BM_StippleOneRun", "BM_StippleSearch"},
                     {"BM_TreeOneRun", "BM_TreeSearch"},
                     {"BM_SketchOneRun", "BM_SketchSearch"},
                     {"BM_PointillismChosenPens", "BM_PointillismMaxPens"},
                     {"BM_SketchChosenPens", "BM_SketchMaxPens"}})
