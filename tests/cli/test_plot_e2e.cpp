// The whole pipeline through the real writers and the simulated plotters over a pty:
// a multi-layer foreign SVG and a stipple, planned, written, streamed and drawn.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

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
