// The whole pipeline through the real writers and the simulated plotters over a pty:
// a multi-layer foreign SVG and a stipple, planned, written, streamed and drawn.
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "test_util.hpp"

namespace {
std::string example(const char* name) { return std::string(STIPPLOT_SOURCE_DIR) + "/examples/" + name; }
nlohmann::json last_json_line(const std::string& out) {
  auto end = out.find_last_not_of('\n');
  auto start = out.rfind('\n', end);
  return nlohmann::json::parse(out.substr(start == std::string::npos ? 0 : start + 1, end + 1));
}
}  // namespace

TEST_CASE("a multi-pen foreign SVG plots on the simulated grbl, pen changes included", "[cli][plot][e2e]") {
  test::TempDir t;
  auto r = test::run_cli("plot " + example("foreign.svg") + " --sim --sim-speedup 400 --json -q --job " +
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
    REQUIRE(test::run_cli("export " + example("foreign.svg") + " --profile " + profile + " -q -o " + exported).exit_code == 0);
    auto r = test::run_cli("plot " + example("foreign.svg") + " --profile " + profile + " --sim --sim-speedup 400 -q --job " + job);
    INFO(profile << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(slurp(job) == slurp(exported));
  }
  auto bad = test::run_cli("plot " + example("foreign.svg") + " --sim -q --job " + t.file("job.hpgl"));
  CHECK(bad.exit_code == 1);
  CHECK(bad.err.find("--job " + t.file("job.hpgl") + ": profile grbl-servo speaks G-code") != std::string::npos);
}

TEST_CASE("a stipple job plots on the simulated HPGL plotter", "[cli][plot][e2e]") {
  test::TempDir t;
  REQUIRE(test::run_cli("stipple " + example("horse.png") + " -a 4 -b 20 -q --landscape --margin 12 --profile hp7475a-a4 -o " +
                        t.file("h.hpgl"))
              .exit_code == 0);
  auto r = test::run_cli("plot " + t.file("h.hpgl") + " --profile hp7475a-a4 --sim --sim-speedup 400 --json -q");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  auto j = last_json_line(r.out);
  CHECK(j["completed"] == true);
  CHECK(j["sim_exact"] == true);
}

TEST_CASE("the simulator's plotted time is within 5% of the planner's estimate", "[cli][plot][e2e][timing]") {
  struct Case {
    const char* profile;
    const char* ext;
    const char* speedup;
  };
  for (const Case& c : {Case{"grbl-servo", "gcode", "10"}, Case{"hp7475a-a4", "hpgl", "20"}}) {
    test::TempDir t;
    const std::string job = t.file(std::string("job.") + c.ext);
    auto e = test::run_cli("export " + example("foreign.svg") + " --profile " + c.profile + " -o " + job + " --json");
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
