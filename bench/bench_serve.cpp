// The studio's preview latency (`stipplot serve`). Run: ./build/bench/bench_serve
// A 12-megapixel photo (coffee.png upscaled to 4243x2828) is uploaded to a studio on the
// loopback; each repetition changes one parameter (stipple's -b) and times the request
// until its answer (preview PNG written, plan estimate and fidelity figure done):
//  - BM_PreviewDragging: the reduced photo the page previews while a control moves;
//  - BM_PreviewReleased: the full-size photo, once the control is let go (the baseline).
// Real time, one request a repetition: the median and the 95th percentile are reported,
// and the ratio of the medians.
#include <httplib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>

#include <benchmark/benchmark.h>

#include "cli/commands.hpp"
#include "image/image.hpp"
#include "photo_12mp.hpp"
#include "preview/preview.hpp"
#include "serve/option_schema.hpp"
#include "serve/studio.hpp"

namespace {

using namespace stipplot;
namespace fs = std::filesystem;

using bench::photo_12mp;

// One studio for the whole run, with the photo uploaded.
struct BenchStudio {
  fs::path dir = fs::temp_directory_path() / "stipplot_bench_serve";
  std::unique_ptr<serve::Studio> studio;
  std::thread thread;
  BenchStudio() {
    fs::remove_all(dir);
    fs::create_directories(dir);
    serve::StudioConfig c;
    c.guard.port = 0;
    c.workdir = dir;
    c.executable = STIPPLOT_BIN;
    CLI::App app;
    cli::register_all(app);
    c.methods["stipple"] = {{"description", ""}, {"options", serve::option_schema(*app.get_subcommand("stipple"), {"--output"})}};
    c.profiles = nlohmann::json::array({{{"name", "grbl-servo"}, {"description", ""}, {"dialect", "gcode"}}});
    studio = std::make_unique<serve::Studio>(c);
    if (!studio->bind()) throw std::runtime_error("cannot bind the studio");
    thread = std::thread([this] { studio->run(); });
    std::ifstream in(photo_12mp(), std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    auto r = client().Post("/api/photo", ss.str(), "image/png");
    if (!r || r->status != 200) throw std::runtime_error("upload failed");
  }
  ~BenchStudio() {
    studio->stop();
    thread.join();
    fs::remove_all(dir);
  }
  httplib::Client client() const {
    httplib::Client c("127.0.0.1", studio->port());
    c.set_read_timeout(300, 0);
    return c;
  }
};

BenchStudio& bench_studio() {
  static BenchStudio s;
  return s;
}

void preview(benchmark::State& state, bool draft) {
  BenchStudio& s = bench_studio();
  auto cl = s.client();
  static int step = 0;
  for (auto _ : state) {
    // One parameter change: -b steps through 14..21 px.
    const std::string body = std::string(R"({"method":"stipple","options":{"-b":")") + std::to_string(14 + step++ % 8) +
                             R"(px"},"draft":)" + (draft ? "true" : "false") + "}";
    const auto t0 = std::chrono::steady_clock::now();
    auto r = cl.Post("/api/preview", body, "application/json");
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (!r || r->status != 200) {
      state.SkipWithError(("preview failed: " + (r ? r->body : std::string("no answer"))).c_str());
      break;
    }
    auto j = nlohmann::json::parse(r->body);
    state.counters["marks"] = j["marks"].get<double>();
  }
}

double percentile(const std::vector<double>& v, double q) {
  std::vector<double> s = v;
  std::sort(s.begin(), s.end());
  const double at = q * static_cast<double>(s.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(at)), hi = static_cast<size_t>(std::ceil(at));
  return s[lo] + (s[hi] - s[lo]) * (at - static_cast<double>(lo));
}

// Console output plus the ratio of the two medians (real time: the work is in children).
class LatencyReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs)
      if (r.aggregate_name == "median") medians_[r.run_name.function_name] = r.GetAdjustedRealTime();
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    auto d = medians_.find("BM_PreviewDragging"), f = medians_.find("BM_PreviewReleased");
    if (d != medians_.end() && f != medians_.end() && d->second > 0)
      std::printf("RATIO (real time, medians) BM_PreviewDragging vs BM_PreviewReleased: %.2fx faster\n", f->second / d->second);
  }

 private:
  std::map<std::string, double> medians_;
};

void BM_PreviewDragging(benchmark::State& state) { preview(state, true); }
void BM_PreviewReleased(benchmark::State& state) { preview(state, false); }

}  // namespace

BENCHMARK(BM_PreviewDragging)
    ->UseManualTime()
    ->Iterations(1)
    ->Repetitions(40)
    ->ComputeStatistics("p95", [](const std::vector<double>& v) { return percentile(v, 0.95); })
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PreviewReleased)
    ->UseManualTime()
    ->Iterations(1)
    ->Repetitions(10)
    ->ComputeStatistics("p95", [](const std::vector<double>& v) { return percentile(v, 0.95); })
    ->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  LatencyReporter rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  benchmark::Shutdown();
  return 0;
}
