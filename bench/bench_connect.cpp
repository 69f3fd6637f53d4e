// Connected stippling (stipple --connect, TSP art). Run: ./build/bench/bench_connect
//  - BM_ConnectSearch: `stipplot stipple coffee.png --connect -o x.svg --page 297x210mm
//    --margin 10 --time 1h` in process (the hour lays 60 % of the tone: a real search)
//    (the statistics, the pilot that fits the tone curve and the time, the search's runs,
//    the plan and the SVG); BM_ConnectOneRun: the same command drawing once at the knob
//    the search chose (--knob). The target: the search within 3x one run.
//  - BM_ConnectUniform/N: connect_on_page on a uniform grey of about N points, against
//    BM_DotsUniform/N, the tone law's dot stipple of the same canvas (the sampling and
//    relaxation they share; the tour and the lift rule are the difference). Counters: the
//    path's constant c = L / sqrt(N A) (L the path through all N points, lifted links
//    included, A the area) and the measured line ink x spacing / pen, kConnectInk's value.
#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/commands.hpp"
#include "methods/stipple/connect.hpp"
#include "ratio_reporter.hpp"
#include "run_command.hpp"

namespace {

namespace fs = std::filesystem;
using namespace stipplot;

std::string example(const char* name) {
  return (fs::path(__FILE__).parent_path().parent_path() / "examples" / name).string();
}

std::string run_command(const std::vector<std::string>& args) { return bench_cli::run_command(args, "connect"); }

std::vector<std::string> command() {
  const std::string svg = (fs::temp_directory_path() / "stipplot_bench_connect.svg").string();
  return {"stipple", example("coffee.png"), "--connect", "-o", svg, "--page", "297x210mm", "--margin", "10",
          "--time", "1h", "--json"};
}

void BM_ConnectSearch(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(run_command(command()));
}
void BM_ConnectOneRun(benchmark::State& state) {
  auto args = command();
  const auto j = nlohmann::json::parse(run_command(args));
  const double k = j["budget"]["knob"].get<double>();
  args.push_back("--knob");
  args.push_back(std::to_string(k));
  for (auto _ : state) benchmark::DoNotOptimize(run_command(args));
  state.counters["knob"] = k;
  state.counters["points"] = j["connect"]["points"].get<double>();
}

// A uniform grey of tone u on a square page whose side gives about `n` points.
StippleCanvas uniform_canvas(double n, double u, double pen) {
  ConnectParams p;
  const double r = connect_spacing_mm(u, pen, p);
  const double side = std::sqrt(n * r * r / pattern_density(100));
  Image img;
  img.width = img.height = 64;
  img.rgb.assign(img.pixels() * 3, static_cast<uint8_t>(std::lround(255 * (1 - u))));
  Placement pl;
  pl.page = {side, side};
  pl.margin_mm = 0;
  pl.pen_width_mm = pen;
  return prepare_stipple(img, StippleMethod::Gray, pl, std::clamp(r / 3, pen / 4, pen / 2));
}

void BM_ConnectUniform(benchmark::State& state) {
  const StippleCanvas c = uniform_canvas(static_cast<double>(state.range(0)), 0.3, 0.3);
  ConnectParams p;
  ConnectStats st;
  Drawing d;
  for (auto _ : state) benchmark::DoNotOptimize(d = connect_on_page(c, p, &st));
  const double area = c.grid.image.width * c.grid.cell_mm * c.grid.image.height * c.grid.cell_mm;
  // The whole path: drawn links plus lifted ones (few on a uniform grey).
  double len = 0;
  std::vector<Vec2> ends;
  for (const Polyline& l : d.layers[0].lines) {
    for (size_t i = 1; i < l.pts.size(); ++i) len += std::hypot(l.pts[i].x - l.pts[i - 1].x, l.pts[i].y - l.pts[i - 1].y);
  }
  const double r = connect_spacing_mm(0.3, 0.3, p);
  state.counters["points"] = static_cast<double>(st.points);
  state.counters["lifted"] = static_cast<double>(st.lifted);
  state.counters["c_drawn"] = len / std::sqrt(static_cast<double>(st.points) * area);
  state.counters["ink_x_r_over_pen"] = len / area * r;
}

void BM_DotsUniform(benchmark::State& state) {
  const StippleCanvas c = uniform_canvas(static_cast<double>(state.range(0)), 0.3, 0.3);
  PageStipple law;
  Drawing d;
  for (auto _ : state) benchmark::DoNotOptimize(d = stipple_on_page(c, law, c.grid.cell_mm, 1));
  state.counters["dots"] = static_cast<double>(d.layers[0].dots.size());
}

BENCHMARK(BM_ConnectSearch)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_ConnectOneRun)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_ConnectUniform)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_DotsUniform)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace

STIPPLOT_BENCH_MAIN({{"BM_ConnectOneRun", "BM_ConnectSearch"},
                     {"BM_DotsUniform/10000", "BM_ConnectUniform/10000"},
                     {"BM_DotsUniform/100000", "BM_ConnectUniform/100000"}})
