// The whole pipeline through the real writers and the simulated plotters over a pty:
// a multi-layer foreign SVG and a stipple, planned, written, streamed and drawn.
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "test_util.hpp"

namespace {
nlohmann::json last_json_line(const std::string& out) {
  auto end = out.find_last_not_of('\n');
  auto start = out.rfind('\n', end);
  return nlohmann::json::parse(out.substr(start == std::string::npos ? 0 : start + 1, end + 1));
}
}  // namespace

TEST_CASE("a multi-pen foreign SVG plots on the simulated grbl, pen changes included", "[cli][plot][e2e]") {
  test::TempDir t;
  auto r = test::run_cli("plot " + test::example("foreign.svg") + " --sim --sim-speedup 400 --json -q --job " +
                         t.file("foreign.gcode") + " --sim-out " + t.file("sim"));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  auto j = last_json_line(r.out);
  CHECK(j["completed"] == true);
  CHECK(j["sim_exact"] == true);  // the simulator drew exactly the job's pen-down segments
  CHECK(j["lines_acked"] == j["lines"]);
  CHECK(std::filesystem::exists(t.file("sim.png")));
}

TEST_CASE("plot plans an SVG as export does, from machine zero", "[cli][plot]") {
  test::TempDir t;
  auto slurp = [](const std::string& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  };
  for (const char* profile : {"grbl-z", "hp7475a-a4"}) {
    const std::string ext = std::string(profile) == "grbl-z" ? ".gcode" : ".hpgl";
    const std::string exported = t.file(std::string("export-") + profile + ext), job = t.file(std::string("plot-") + profile + ext);
    REQUIRE(test::run_cli("export " + test::example("foreign.svg") + " --profile " + profile + " -q -o " + exported).exit_code == 0);
    auto r = test::run_cli("plot " + test::example("foreign.svg") + " --profile " + profile + " --sim --sim-speedup 400 -q --job " + job);
    INFO(profile << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(slurp(job) == slurp(exported));
  }
  auto bad = test::run_cli("plot " + test::example("foreign.svg") + " --sim -q --job " + t.file("job.hpgl"));
  CHECK(bad.exit_code == 1);
  CHECK(bad.err.find("--job " + t.file("job.hpgl") + ": profile grbl-servo speaks G-code") != std::string::npos);
}

TEST_CASE("a stipple job plots on the simulated HPGL plotter", "[cli][plot][e2e]") {
  test::TempDir t;
  REQUIRE(test::run_cli("stipple " + test::example("horse.png") + " -a 4px -b 20px -q --landscape --margin 12 --profile hp7475a-a4 -o " +
                        t.file("h.hpgl"))
              .exit_code == 0);
  auto r = test::run_cli("plot " + t.file("h.hpgl") + " --profile hp7475a-a4 --sim --sim-speedup 400 --json -q");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  auto j = last_json_line(r.out);
  CHECK(j["completed"] == true);
  CHECK(j["sim_exact"] == true);
}

TEST_CASE("the simulator's plotted time is within 5% of the planner's estimate", "[cli][plot][e2e][timing][realtime]") {
  struct Case {
    const char* profile;
    const char* ext;
    const char* speedup;
  };
  for (const Case& c : {Case{"grbl-servo", "gcode", "10"}, Case{"hp7475a-a4", "hpgl", "20"}}) {
    test::TempDir t;
    const std::string job = t.file(std::string("job.") + c.ext);
    auto e = test::run_cli("export " + test::example("foreign.svg") + " --profile " + c.profile + " -o " + job + " --json");
    REQUIRE(e.exit_code == 0);
    const double estimate = last_json_line(e.out)["plan"]["total"]["seconds"].get<double>();
    auto r = test::run_cli("plot " + job + " --profile " + c.profile + " --sim --sim-speedup " + c.speedup + " --json -q");
    INFO(c.profile << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    const double simulated = last_json_line(r.out)["sim_plot_s"].get<double>();
    INFO(c.profile << " estimate " << estimate << " s, simulated " << simulated << " s");
    CHECK(std::abs(simulated / estimate - 1) < 0.05);
  }
}

TEST_CASE("the plot's ETA at 25, 50 and 75 % is within 5 % of the time really left", "[cli][plot][e2e][timing][realtime]") {
  struct Case {
    const char* profile;
    const char* ext;
    const char* make;
    const char* speedup;
  };
  // About 20-30 s of simulated plotting each, at a speed-up low enough that even a busy host
  // keeps the simulated planner fed: foreign.svg's strokes on grbl (62 s of plan), a
  // stipple's dots on the HPGL plotter (2 min; an HPGL instruction is a whole stroke, the
  // finest a plotter's buffer says it has done, so strokes would blur the measure).
  for (const Case& c : {Case{"grbl-servo", "gcode", "export examples/foreign.svg", "2"},
                        Case{"hp7475a-a4", "hpgl", "stipple examples/coffee.png --dots --time 2min", "6"}}) {
    test::TempDir t;
    const std::string job = t.file(std::string("job.") + c.ext);
    std::string make = c.make;
    make.replace(make.find("examples/"), 9, std::string(STIPPLOT_SOURCE_DIR) + "/examples/");
    auto e = test::run_cli(make + " --profile " + c.profile + " -o " + job + " -q");
    REQUIRE(e.exit_code == 0);
    auto r = test::run_cli("plot " + job + " --profile " + c.profile + " --sim --sim-speedup " + c.speedup + " --json");
    INFO(c.profile << ": " << r.err.substr(0, 2000));
    REQUIRE(r.exit_code == 0);
    const double end_s = last_json_line(r.out)["streamed_s"].get<double>();
    // The progress lines (JSON on stderr, one a second): the first at or past each mark.
    std::istringstream lines(r.err);
    std::string l;
    std::vector<double> marks = {0.25, 0.5, 0.75};
    size_t next = 0;
    while (std::getline(lines, l) && next < marks.size()) {
      if (l.rfind("{\"", 0) != 0) continue;
      const auto p = nlohmann::json::parse(l);
      if (!p.contains("eta_s") || p["progress"].get<double>() < marks[next]) continue;
      const double left = end_s - p["elapsed_s"].get<double>(), eta = p["eta_s"].get<double>();
      INFO(c.profile << " at " << p["progress"].get<double>() * 100 << " %: ETA " << eta << " s, really " << left
                     << " s left (the stream took " << end_s << " s)");
      CHECK(std::abs(eta - left) <= 0.05 * left);
      ++next;
    }
    CHECK(next == marks.size());
  }
}
