// Keeping the machine fed: character counting vs send-and-wait, streamed through the
// termios serial transport on a pty to the simulated grbl, with a 115200-baud wire
// (10 bits a byte) and a USB-serial round trip of 4 ms, on a job of many short
// segments (curves flattened to 0.25 mm). Reported per mode: plot time (device
// seconds) and the share of it the planner sat empty while lines remained.
//
//   bench_streaming [--speedup=N] [google benchmark flags]
//
// The simulator runs N times faster than real time, the wire and latency included,
// so the proportions are those of the real machine while the benchmark takes seconds.
// BM_StreamingJournal: the same job with character counting, without a journal and with
// one (every ack, every status report's proof "pos N X Y Z", fsync'd every 100 ms as
// `stipplot plot` keeps it): the journal's cost in plot time.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <unistd.h>

#include "drivers/job/gcode_reader.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/grbl/streamer.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "sim/grbl_sim.hpp"

using namespace stipplot;

namespace {

double g_speedup = 10;

// Curves of many 0.25 mm segments (what a tree drawing or a foreign SVG flattens to).
std::string curves_job(int curves, int segs) {
  std::string g = "G21\nG90\nM5\n";
  char b[96];
  for (int c = 0; c < curves; ++c) {
    double cx = 30 + 25 * (c % 5), cy = 30 + 25 * (c / 5);
    double r = 5 + c % 7;
    double step = 0.25 / r;  // 0.25 mm along the curve
    auto pt = [&](int i, double& x, double& y) {
      double a = i * step;
      double rr = r * (1 + 0.3 * std::sin(3 * a));
      x = cx + rr * std::cos(a);
      y = cy + rr * std::sin(a);
    };
    double x, y;
    pt(0, x, y);
    std::snprintf(b, sizeof b, "G0 X%.3f Y%.3f\nM3 S30\nG4 P0.1\n", x, y);
    g += b;
    for (int i = 1; i <= segs; ++i) {
      pt(i, x, y);
      std::snprintf(b, sizeof b, "G1 X%.3f Y%.3f F3000\n", x, y);
      g += b;
    }
    g += "M5\nG4 P0.1\n";
  }
  return g;
}

struct Outcome {
  double plot_s, starved_share, real_s;
  size_t overflow;
};

Outcome run(io::grbl::Mode mode, const io::Job& job, io::Journal* journal = nullptr) {
  sim::GrblSimConfig c;
  c.speedup = g_speedup;
  c.link.baud = 115200;
  c.link.latency_ms = 4;
  c.machine.accel_mm_s2 = {1000, 1000, 1000};
  c.machine.junction_deviation_mm = 0.01;
  sim::GrblSim sim(c);
  io::PosixSerial port(sim.open_pty(), {});
  io::grbl::Options o;
  o.mode = mode;
  io::grbl::Streamer st(port, o);
  st.connect();
  auto t0 = std::chrono::steady_clock::now();
  st.stream(job, 0, {}, journal);
  sim.wait_idle(600);
  double real = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  sim::SimStats s = sim.stats();
  return {s.plot_time(), s.starved_share(), real, s.rx_overflow};
}

void BM_StreamingModes(benchmark::State& state) {
  io::Job job = io::parse_gcode_job(curves_job(10, 250));
  Outcome cc{}, sw{};
  for (auto _ : state) {
    cc = run(io::grbl::Mode::CharacterCounting, job);
    sw = run(io::grbl::Mode::SendAndWait, job);
  }
  state.counters["lines"] = static_cast<double>(job.lines.size());
  state.counters["speedup"] = g_speedup;
  state.counters["counting_plot_s"] = cc.plot_s;
  state.counters["counting_starved_pct"] = 100 * cc.starved_share;
  state.counters["wait_plot_s"] = sw.plot_s;
  state.counters["wait_starved_pct"] = 100 * sw.starved_share;
  state.counters["wait_over_counting"] = cc.plot_s > 0 ? sw.plot_s / cc.plot_s : 0;
  state.counters["rx_overflow"] = static_cast<double>(cc.overflow + sw.overflow);
}
BENCHMARK(BM_StreamingModes)->Iterations(1)->Unit(benchmark::kSecond);

// Records of a kind in a journal file ("ack ", "pos ").
size_t count_records(const std::string& path, const std::string& kind) {
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (!f) return 0;
  size_t n = 0;
  char line[256];
  while (std::fgets(line, sizeof line, f)) n += std::strncmp(line, kind.c_str(), kind.size()) == 0;
  std::fclose(f);
  return n;
}

void BM_StreamingJournal(benchmark::State& state) {
  io::Job job = io::parse_gcode_job(curves_job(10, 250));
  char tmpl[] = "/tmp/stipplot-bench-journal-XXXXXX";
  const int fd = ::mkstemp(tmpl);
  if (fd >= 0) ::close(fd);
  const std::string path = tmpl;
  Outcome plain{}, journalled{};
  size_t acks = 0, proofs = 0;
  for (auto _ : state) {
    plain = run(io::grbl::Mode::CharacterCounting, job);
    {
      io::JournalHeader h{"bench.gcode", "0", "gcode", "", "", job.lines.size()};
      io::Journal journal(path, h);
      journalled = run(io::grbl::Mode::CharacterCounting, job, &journal);
    }
    acks = count_records(path, "ack ");
    proofs = count_records(path, "pos ");
  }
  std::remove(path.c_str());
  state.counters["lines"] = static_cast<double>(job.lines.size());
  state.counters["plain_plot_s"] = plain.plot_s;
  state.counters["journal_plot_s"] = journalled.plot_s;
  state.counters["journal_over_plain"] = plain.plot_s > 0 ? journalled.plot_s / plain.plot_s : 0;
  state.counters["journal_starved_pct"] = 100 * journalled.starved_share;
  state.counters["ack_records"] = static_cast<double>(acks);
  state.counters["pos_records"] = static_cast<double>(proofs);
  state.counters["proofs_per_s"] = journalled.plot_s > 0 ? static_cast<double>(proofs) / journalled.plot_s : 0;
}
BENCHMARK(BM_StreamingJournal)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--speedup=", 10) == 0) {
      g_speedup = std::atof(argv[i] + 10);
      for (int k = i; k < argc - 1; ++k) argv[k] = argv[k + 1];
      --argc;
      --i;
    }
  }
  if (!(g_speedup > 0)) {
    std::fprintf(stderr, "--speedup must be > 0\n");
    return 1;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
