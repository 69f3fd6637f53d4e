// Writers and the SVG reader on large inputs.
//  - G-code / HPGL of a 200,000-stroke plan (stipple-sized: 190k dots + 10k polylines)
//    into a line sink (what a driver streams) and into a file (atomic). O(points).
//  - The planned-order SVG of the same plan. O(points).
//  - Reading a large foreign SVG (curves, arcs, transforms) back into a Drawing.
//    O(elements + flattened points).
// Baseline for the writers: formatting the same points as bare "x y" text lines, the
// least any text writer can do.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "drivers/writers/gcode_writer.hpp"
#include "drivers/writers/hpgl_writer.hpp"
#include "svg/planned_svg.hpp"
#include "drivers/device/profile.hpp"
#include "svg/svg_reader.hpp"
#include "util/rng.hpp"
#include "ratio_reporter.hpp"

using namespace stipplot;

namespace {

Plan big_plan(double w, double h) {
  Rng rng(42);
  Plan p;
  p.page = {w, h};
  PlannedLayer l;
  for (int i = 0; i < 190'000; ++i) l.strokes.push_back({{{20 + rng.uniform() * (w - 40), 20 + rng.uniform() * (h - 40)}}});
  for (int i = 0; i < 10'000; ++i) {
    Stroke s;
    Vec2 q{20 + rng.uniform() * (w - 40), 20 + rng.uniform() * (h - 40)};
    for (int k = 0; k < 8; ++k) s.pts.push_back({q.x + k * 0.7, q.y + std::sin(k) * 0.5});
    l.strokes.push_back(s);
  }
  p.layers.push_back(l);
  return p;
}

const Plan& a4_plan() {
  static Plan p = big_plan(210, 297);
  return p;
}
const Plan& a3_plan() {
  static Plan p = big_plan(420, 297);
  return p;
}

size_t count_points(const Plan& p) {
  size_t n = 0;
  for (const auto& l : p.layers)
    for (const auto& s : l.strokes) n += s.pts.size();
  return n;
}

void BM_BaselinePlainText(benchmark::State& st) {
  const Plan& plan = a4_plan();
  for (auto _ : st) {
    size_t bytes = 0;
    char buf[64];
    for (const auto& l : plan.layers)
      for (const auto& s : l.strokes)
        for (const auto& q : s.pts) bytes += static_cast<size_t>(std::snprintf(buf, sizeof buf, "%.2f %.2f", q.x, q.y));
    benchmark::DoNotOptimize(bytes);
  }
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations() * count_points(plan)));
}
BENCHMARK(BM_BaselinePlainText)->Unit(benchmark::kMillisecond);

void BM_GcodeToSink(benchmark::State& st) {
  const Plan& plan = a4_plan();
  DeviceProfile prof = find_profile("grbl-servo");
  for (auto _ : st) {
    size_t bytes = 0, lines = 0;
    write_gcode(plan, prof, [&](std::string_view l) {
      bytes += l.size();
      ++lines;
    });
    benchmark::DoNotOptimize(bytes);
    st.counters["lines"] = static_cast<double>(lines);
  }
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations() * count_points(plan)));
}
BENCHMARK(BM_GcodeToSink)->Unit(benchmark::kMillisecond);

void BM_GcodeToFile(benchmark::State& st) {
  const Plan& plan = a4_plan();
  DeviceProfile prof = find_profile("grbl-servo");
  auto path = (std::filesystem::temp_directory_path() / "stipplot_bench.gcode").string();
  for (auto _ : st) write_gcode_file(plan, prof, path);
  st.counters["bytes"] = static_cast<double>(std::filesystem::file_size(path));
  std::filesystem::remove(path);
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations() * count_points(plan)));
}
BENCHMARK(BM_GcodeToFile)->Unit(benchmark::kMillisecond);

void BM_HpglToSink(benchmark::State& st) {
  const Plan& plan = a3_plan();
  DeviceProfile prof = find_profile("roland-dxy1300");
  for (auto _ : st) {
    size_t bytes = 0;
    write_hpgl(plan, prof, [&](std::string_view l) { bytes += l.size(); });
    benchmark::DoNotOptimize(bytes);
  }
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations() * count_points(plan)));
}
BENCHMARK(BM_HpglToSink)->Unit(benchmark::kMillisecond);

void BM_PlannedSvgString(benchmark::State& st) {
  const Plan& plan = a4_plan();
  for (auto _ : st) benchmark::DoNotOptimize(planned_svg_string(plan).size());
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations() * count_points(plan)));
}
BENCHMARK(BM_PlannedSvgString)->Unit(benchmark::kMillisecond);

// A foreign SVG: 20,000 groups, each a transformed path with a cubic, a quadratic and an arc,
// plus a polyline and a circle.
const std::string& big_svg() {
  static std::string svg = [] {
    Rng rng(7);
    std::string s =
        R"(<svg xmlns="http://www.w3.org/2000/svg" width="420mm" height="297mm" viewBox="0 0 1587.4 1122.5">)";
    char buf[512];
    for (int i = 0; i < 20'000; ++i) {
      double x = rng.uniform() * 1500, y = rng.uniform() * 1050, a = rng.uniform() * 360;
      std::snprintf(buf, sizeof buf,
                    "<g transform=\"translate(%.2f %.2f) rotate(%.1f)\" stroke=\"#%02x0000\" fill=\"none\">"
                    "<path d=\"M0 0 C 10 -20 30 -20 40 0 Q 50 20 60 0 A 15 10 30 0 1 90 10 l 5 5 h 3 v -4 z\"/>"
                    "<polyline points=\"0,30 10,35 20,30 30,35\"/><circle cx=\"50\" cy=\"40\" r=\"6\"/></g>",
                    x, y, a, i % 4 * 60);
      s += buf;
    }
    s += "</svg>";
    return s;
  }();
  return svg;
}

void BM_SvgRead(benchmark::State& st) {
  const std::string& svg = big_svg();
  size_t pts = 0;
  for (auto _ : st) {
    Drawing d = parse_svg(svg, "bench.svg");
    pts = 0;
    for (const auto& l : d.layers)
      for (const auto& pl : l.lines) pts += pl.pts.size();
    benchmark::DoNotOptimize(pts);
  }
  st.counters["MB"] = static_cast<double>(svg.size()) / 1e6;
  st.counters["points_out"] = static_cast<double>(pts);
  st.SetBytesProcessed(static_cast<int64_t>(st.iterations() * svg.size()));
}
BENCHMARK(BM_SvgRead)->Unit(benchmark::kMillisecond);

// 200,000 dots as stipplot writes them, in one Inkscape layer: the streaming reader
// (arg 1) against reading through tinyxml2's tree of the whole file (arg 0, the
// baseline), and the stream with expat on a thread of its own (arg 2, the default for a
// file of 4 MB or more on two threads) against the stream on one (arg 1). Same drawing either way (tests/svg); the memory figure is the README's
// 1M-dot export under /usr/bin/time -v.
const std::string& dots_svg() {
  static std::string svg = [] {
    Rng rng(11);
    std::string s =
        R"(<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" )"
        R"(width="200mm" height="200mm" viewBox="0 0 200 200"><g id="layer1" inkscape:groupmode="layer" )"
        R"(inkscape:label="1 black" stroke="#000000" stroke-width="0.3" fill="none">)";
    char buf[160];
    for (int i = 0; i < 200'000; ++i) {
      std::snprintf(buf, sizeof buf, "\n<circle cx=\"%.3f\" cy=\"%.3f\" r=\"0.15\" fill=\"#000000\" stroke=\"none\"/>",
                    rng.uniform() * 200, rng.uniform() * 200);
      s += buf;
    }
    s += "</g></svg>";
    return s;
  }();
  return svg;
}

void BM_SvgReadDots(benchmark::State& st) {
  const std::string& svg = dots_svg();
  SvgReadOptions ro;
  ro.stream = st.range(0) >= 1;
  ro.tokenize_apart_from_bytes = st.range(0) == 2 ? 0 : SIZE_MAX;
  size_t dots = 0;
  for (auto _ : st) {
    Drawing d = parse_svg(svg, "dots.svg", ro);
    dots = 0;
    for (const auto& l : d.layers) dots += l.dots.size();
    benchmark::DoNotOptimize(dots);
  }
  st.counters["dots"] = static_cast<double>(dots);
  st.SetBytesProcessed(static_cast<int64_t>(st.iterations() * svg.size()));
}
BENCHMARK(BM_SvgReadDots)->ArgName("stream")->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

STIPPLOT_BENCH_MAIN({{"BM_SvgReadDots/stream:1", "BM_SvgReadDots/stream:0"},
                     {"BM_SvgReadDots/stream:2", "BM_SvgReadDots/stream:1"}});
