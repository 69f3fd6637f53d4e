#pragma once
// Jobs for the firmware tests, made by today's stipplot CLI, and `stipplot plot` run
// against the firmware's port: small enough that each plots in a few simulated seconds.
#include <nlohmann/json.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "firmware/grbl_firmware.hpp"
#include "firmware/job_compare.hpp"
#include "test_util.hpp"

namespace firmware::jobs {

inline std::string example(const std::string& name) { return std::string(STIPPLOT_SOURCE_DIR) + "/examples/" + name; }

inline nlohmann::json last_json(const std::string& out) {
  auto end = out.find_last_not_of('\n');
  if (end == std::string::npos) return {};
  auto start = out.rfind('\n', end);
  try {
    const size_t from = start == std::string::npos ? 0 : start + 1;
    return nlohmann::json::parse(out.substr(from, end + 1 - from));
  } catch (const nlohmann::json::exception&) {
    return {};
  }
}

// A rectangle, a circle and a zigzag on a 40 x 30 mm page: 3 strokes, 64 G1 moves.
inline std::string small_svg(const test::TempDir& t) {
  std::string p = t.file("small.svg");
  std::ofstream(p) << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"40mm\" height=\"30mm\" viewBox=\"0 0 40 30\">\n"
                      "  <rect x=\"3\" y=\"3\" width=\"12\" height=\"10\" fill=\"none\" stroke=\"black\"/>\n"
                      "  <circle cx=\"28\" cy=\"10\" r=\"6\" fill=\"none\" stroke=\"black\"/>\n"
                      "  <polyline points=\"4,26 10,18 16,26 22,18 28,26 34,18\" fill=\"none\" stroke=\"black\"/>\n"
                      "</svg>\n";
  return p;
}

struct Job {
  std::string path;
  double estimate_s = 0;  // plan.total.seconds
};

// `stipplot export SVG --profile P -o OUT --json`.
inline Job export_job(const std::string& svg, const std::string& profile, const std::string& out,
                      const std::string& extra = "") {
  auto r = test::run_cli("export " + svg + " --profile " + profile + " -o " + out + " --json " + extra);
  if (r.exit_code != 0) throw std::runtime_error("stipplot export failed: " + r.err);
  return {out, last_json(r.out)["plan"]["total"]["seconds"].get<double>()};
}

// `stipplot stipple examples/horse.png` on a small page: -a 80px -b 120px gives 9 dots.
inline Job dots_job(const std::string& profile, const std::string& out,
                    const std::string& extra = "--page 30x25mm --margin 2 -a 80px -b 120px") {
  auto r = test::run_cli("stipple " + example("horse.png") + " " + extra + " --profile " + profile + " -o " + out + " --json");
  if (r.exit_code != 0) throw std::runtime_error("stipplot stipple failed: " + r.err);
  return {out, last_json(r.out)["plan"]["total"]["seconds"].get<double>()};
}

inline Job tree_job(const std::string& profile, const std::string& out,
                    const std::string& extra = "--page 40x30mm --margin 2 -a 7.5 -b 12") {
  // --law linear: the paper's tree spans the whole picture. The default tone law leaves
  // horse.png's white ground empty, and on these small pages the job shrank to a couple of
  // dozen lines, too few for a fault "mid-plot" (a soft reset at half its lines landed in
  // the first rapid move).
  auto r = test::run_cli("tree " + example("horse.png") + " " + extra + " --law linear --profile " + profile + " -o " + out +
                         " --json");
  if (r.exit_code != 0) throw std::runtime_error("stipplot tree failed: " + r.err);
  return {out, last_json(r.out)["plan"]["total"]["seconds"].get<double>()};
}

// The job without its M0 pen-change pauses: grbl holds there until the operator (or the
// host's next status poll) sends cycle start, a wait no estimate can know.
inline std::string without_pauses(const std::string& path) {
  std::string out;
  for (const std::string& l : gcode_lines(test::read_file(path)))
    if (grbl_line_filter(l).rfind("M0", 0) != 0) out += l + "\n";
  const std::string p = path + ".nopause.gcode";
  std::ofstream(p) << out;
  return p;
}

struct Plot {
  test::RunResult run;
  nlohmann::json summary;  // the --json summary line ({} if none)
  bool completed() const { return run.exit_code == 0 && summary.value("completed", false); }
};

// `stipplot plot JOB --profile P --port PORT --json -q EXTRA` (or --resume JOB).
inline Plot plot(const std::string& job, const std::string& profile, const std::string& port, const std::string& extra = "",
                 bool resume = false) {
  Plot p;
  p.run = test::run_cli("plot " + std::string(resume ? "--resume " : "") + job + " --profile " + profile + " --port " + port +
                        " --json -q " + extra);
  p.summary = last_json(p.run.out);
  return p;
}

// The job lines (grbl's filtered form) the firmware answered with "ok", in order.
inline std::vector<std::string> client_lines_ok(const std::vector<HostLine>& lines) {
  std::vector<std::string> out;
  for (const HostLine& l : lines) {
    std::string f = grbl_line_filter(l.text);
    if (l.from_client && l.reply == HostLine::Reply::Ok && !f.empty() && f[0] != '$') out.push_back(f);
  }
  return out;
}

inline std::vector<std::string> job_lines(const std::string& gcode) {
  std::vector<std::string> out;
  for (const std::string& l : gcode_lines(gcode)) {
    std::string f = grbl_line_filter(l);
    if (!f.empty()) out.push_back(f);
  }
  return out;
}

inline size_t rx_drops(const FirmwareRecord& r) {
  size_t n = 0;
  for (const SessionRecord& s : r.sessions) n += s.rx_overruns;
  return n;
}

// `curves` closed wobbly curves flattened to 250 segments of 0.25 mm each, a servo pen
// down for each (curves as a tree drawing or a foreign SVG flattens to): the streaming jobs.
inline std::string curves_gcode(int curves) {
  std::string g = "G21\nG90\nM5\n";
  char b[96];
  for (int c = 0; c < curves; ++c) {
    const int cols = curves > 4 ? 5 : 2;
    double cx = 30 + 25 * (c % cols), cy = 30 + 25 * (c / cols), r = 5 + c % 7, step = 0.25 / r;
    auto pt = [&](int i, double& x, double& y) {
      double a = i * step, rr = r * (1 + 0.3 * std::sin(3 * a));
      x = cx + rr * std::cos(a);
      y = cy + rr * std::sin(a);
    };
    double x, y;
    pt(0, x, y);
    std::snprintf(b, sizeof b, "G0 X%.2f Y%.2f\nM3 S1000\nG4 P0.1\n", x, y);
    g += b;
    for (int i = 1; i <= 250; ++i) {
      pt(i, x, y);
      std::snprintf(b, sizeof b, "G1 X%.2f Y%.2f F3000\n", x, y);
      g += b;
    }
    g += "M5\nG4 P0.1\n";
  }
  return g;
}

// What to look at when a test fails: the blocks grbl planned and how far each ran, every
// line with its reply, and everything grbl said.
inline void dump(const FirmwareRecord& rec) {
  for (const SessionRecord& s : rec.sessions) std::printf("%s", describe(s, rec.settings).c_str());
  const char* reply[] = {"none", "ok", "error", "flushed"};
  for (const HostLine& l : rec.lines)
    std::printf("  host %.3f %s%s -> %s %.3f\n", l.t_sent, l.from_client ? "" : "[harness] ", l.text.c_str(),
                reply[static_cast<int>(l.reply)], l.t_reply);
  for (const DeviceLine& l : rec.device)
    std::printf("  grbl %.3f%s %s\n", l.t, l.forwarded ? "" : " (not forwarded)", l.text.c_str());
  std::fflush(stdout);
}

}  // namespace firmware::jobs
