// stipplot pen on the EBB's own firmware (ebb_sim over a pty): the servo's positions set in
// percent as axicli sets them, and the pen raised, lowered, toggled and cycled; the judge
// is the firmware's event log (the servo's pulse width, the pen state).
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/device/profile.hpp"
#include "ebb/ebb_sim.hpp"
#include "test_util.hpp"

namespace {

nlohmann::json pen_json(const std::string& out) { return nlohmann::json::parse(out.substr(0, out.find('\n'))); }

// The firmware log's SERVO pulse widths (with their pin and time) and PEN states, in order.
struct PenEvents {
  std::vector<int> pulses;
  std::vector<std::string> pins;  // RP4: port B pin 1, the standard servo; RP5: pin 2
  std::vector<double> times;
  std::vector<std::string> pens;
};
PenEvents pen_events(const std::string& log) {
  PenEvents e;
  std::ifstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string t, ev, a;
    s >> t >> ev;
    if (ev == "SERVO") {
      int w = 0;
      s >> a >> w;
      e.pulses.push_back(w);
      e.pins.push_back(a);
      e.times.push_back(std::stod(t));
    } else if (ev == "PEN") {
      s >> a;
      e.pens.push_back(a);
    }
  }
  return e;
}

// The distinct widths the servo rested at on `pin`, in order: each a change that stays
// put until the next move (a slew's intermediate widths pass by).
std::vector<int> rests_on(const PenEvents& e, const std::string& pin, const std::vector<int>& targets) {
  std::vector<int> rests;
  for (size_t i = 0; i < e.pulses.size(); ++i)
    if (e.pins[i] == pin && std::find(targets.begin(), targets.end(), e.pulses[i]) != targets.end() &&
        (rests.empty() || rests.back() != e.pulses[i]))
      rests.push_back(e.pulses[i]);
  return rests;
}

// A small drawing: two strokes.
std::string two_strokes(test::TempDir& t) {
  const std::string svg = t.file("two.svg");
  std::ofstream(svg) << R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="80mm" viewBox="0 0 100 80">)"
                     << R"(<path d="M10 10 L50 10 L50 40" stroke="black" fill="none"/>)"
                     << R"(<path d="M60 60 L80 70" stroke="black" fill="none"/></svg>)";
  return svg;
}

std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

}  // namespace

TEST_CASE("stipplot pen sets the EBB's pen heights in percent and moves the pen, as the firmware's servo shows", "[ebb]") {
  test::TempDir t;
  const stipplot::DeviceProfile prof = stipplot::find_profile("axidraw-v3");
  const int min = prof.ebb.servo_min, range = prof.ebb.servo_max - prof.ebb.servo_min;
  ebbtest::EbbBoard board(t.file("fw.log"));
  auto down = test::run_cli("pen down --profile axidraw-v3 --port " + board.port() + " --pos-down 25 --json");
  INFO(down.err);
  REQUIRE(down.exit_code == 0);
  const auto d = pen_json(down.out);
  CHECK(d["pen"] == "down");
  CHECK(d["servo_down"].get<int>() == min + static_cast<int>(std::lround(range * 0.25)));
  CHECK(d["servo_up"].get<int>() == min + static_cast<int>(std::lround(range * 0.60)));  // the profile's
  auto up = test::run_cli("pen toggle --profile axidraw-v3 --port " + board.reconnect() + " --pos-up 70 --json");
  INFO(up.err);
  REQUIRE(up.exit_code == 0);
  CHECK(pen_json(up.out)["pen"] == "up");
  auto cycle = test::run_cli("pen cycle --profile axidraw-v3 --port " + board.reconnect() + " --pos-up 70 --pos-down 25");
  INFO(cycle.err);
  REQUIRE(cycle.exit_code == 0);
  CHECK(cycle.out.find("pen up on ") == 0);
  board.finish();
  const PenEvents e = pen_events(t.file("fw.log"));
  // The servo slews to each position in turn and rests there: 25 %, 70 %, 25 %, 70 %.
  std::vector<int> rests;
  for (size_t i = 0; i < e.pulses.size(); ++i)
    for (const double pct : {25.0, 70.0})
      if (e.pulses[i] == min + static_cast<int>(std::lround(range * pct / 100)) && (rests.empty() || rests.back() != e.pulses[i]))
        rests.push_back(e.pulses[i]);
  const int p25 = min + static_cast<int>(std::lround(range * 0.25)), p70 = min + static_cast<int>(std::lround(range * 0.70));
  CHECK(rests == std::vector<int>{p25, p70, p25, p70});
  REQUIRE(!e.pens.empty());
  CHECK(e.pens.back() == "UP");
}

TEST_CASE("stipplot pen refuses a height out of range and a plotter that is not an EBB, in one line", "[ebb]") {
  auto r = test::run_cli("pen down --pos-down 120 --port /dev/null");
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("--pos-down") != std::string::npos);
  CHECK(test::count_lines(r.err) == 1);
  auto g = test::run_cli("pen up --profile grbl-servo --port /dev/null");
  CHECK(g.exit_code != 0);
  CHECK(g.err.find("not an EiBotBoard") != std::string::npos);
  CHECK(test::count_lines(g.err) == 1);
}

TEST_CASE("A NextDraw's brushless pen lift: one servo channel (SC,8,1) and SP on pin RB2, as the firmware shows", "[ebb]") {
  test::TempDir t;
  const stipplot::DeviceProfile prof = stipplot::find_profile("nextdraw-8511");
  const stipplot::EbbPen pen = stipplot::ebb_pen(prof.pen, prof.ebb);
  REQUIRE(pen.up == 9720);  // 5400 + 72 * 60
  REQUIRE(pen.down == 8280);
  // The job: SC,8,1 before the first SP, every SP on pin 2.
  auto r = test::run_cli("export " + two_strokes(t) + " --profile nextdraw-8511 -q -o " + t.file("nd.ebb"));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto job = lines_of(t.file("nd.ebb"));
  const auto sc8 = std::find(job.begin(), job.end(), "SC,8,1");
  REQUIRE(sc8 != job.end());
  size_t sps = 0;
  for (auto it = job.begin(); it != job.end(); ++it)
    if (it->rfind("SP,", 0) == 0) {
      ++sps;
      CHECK(it > sc8);
      CHECK(it->substr(it->rfind(',')) == ",2");
    }
  CHECK(sps == 5);  // up at the start, then down and up per stroke
  ebbtest::run_job_file(t.file("nd.ebb"), t.file("job.log"));
  const PenEvents j = pen_events(t.file("job.log"));
  CHECK(std::count(j.pins.begin(), j.pins.end(), "RP4") == 0);  // nothing on the standard servo's pin
  CHECK(rests_on(j, "RP5", {pen.up, pen.down}) == std::vector<int>{pen.up, pen.down, pen.up, pen.down, pen.up});
  CHECK(std::count(j.pens.begin(), j.pens.end(), "DOWN") == 2);
  // One channel: the pulse is updated every 3 ms (8 channels: every 24 ms), so the first
  // lowering (1440 units at 154 an update) is over within its SP's 47 ms.
  size_t from = 0;
  while (from < j.pulses.size() && !(from > 0 && j.pulses[from - 1] == pen.up && j.pulses[from] < pen.up)) ++from;
  REQUIRE(from < j.pulses.size());
  size_t to = from;
  while (to < j.pulses.size() && j.pulses[to] != pen.down) ++to;
  REQUIRE(to < j.pulses.size());
  CHECK(to - from == 9);  // ceil(1440 / 154) updates after the first
  for (size_t i = from + 1; i <= to; ++i) CHECK(j.times[i] - j.times[i - 1] == Approx(0.003).margin(1e-6));
  CHECK(j.times[to] - j.times[from] + 0.003 <= pen.lower_ms / 1000.0);
  // stipplot pen drives the same lift: down and up on pin 2.
  ebbtest::EbbBoard board(t.file("fw.log"));
  auto c = test::run_cli("pen cycle --profile nextdraw-8511 --port " + board.port() + " --pos-down 30");
  INFO(c.err);
  REQUIRE(c.exit_code == 0);
  board.finish();
  const PenEvents e = pen_events(t.file("fw.log"));
  const int p30 = 5400 + 72 * 30;
  CHECK(std::count(e.pins.begin(), e.pins.end(), "RP4") == 0);
  CHECK(rests_on(e, "RP5", {pen.up, p30}) == std::vector<int>{p30, pen.up});
  REQUIRE(!e.pens.empty());
  CHECK(e.pens.back() == "UP");
}

TEST_CASE("plot and export take --pos-up/--pos-down on an EBB: the job's servo rests where they say", "[ebb]") {
  test::TempDir t;
  const stipplot::DeviceProfile prof = stipplot::find_profile("axidraw-v3");
  const int min = prof.ebb.servo_min, range = prof.ebb.servo_max - prof.ebb.servo_min;
  auto at = [&](double pct) { return min + static_cast<int>(std::lround(range * pct / 100)); };
  const std::string svg = two_strokes(t);
  // export: the job's SC,4/SC,5 and the firmware's servo follow the percentages given.
  auto r = test::run_cli("export " + svg + " --profile axidraw-v3 --pos-up 80 --pos-down 10 --json -o " + t.file("e.ebb"));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("\"pen_heights_pct\":[80.0,10.0]") != std::string::npos);
  const auto job = lines_of(t.file("e.ebb"));
  CHECK(std::find(job.begin(), job.end(), "SC,4," + std::to_string(at(80))) != job.end());
  CHECK(std::find(job.begin(), job.end(), "SC,5," + std::to_string(at(10))) != job.end());
  ebbtest::run_job_file(t.file("e.ebb"), t.file("e.log"));
  CHECK(rests_on(pen_events(t.file("e.log")), "RP4", {at(80), at(10), at(60), at(30)}) ==
        std::vector<int>{at(80), at(10), at(80), at(10), at(80)});
  // plot: an SVG planned with one height given; the other is the profile's (30 %).
  ebbtest::EbbBoard board(t.file("fw.log"));
  auto p = test::run_cli("plot " + svg + " --profile axidraw-v3 --pos-up 75 --job " + t.file("p.ebb") + " --port " +
                         board.port() + " --pen-change continue -q");
  INFO(p.err);
  REQUIRE(p.exit_code == 0);
  board.finish();
  CHECK(rests_on(pen_events(t.file("fw.log")), "RP4", {at(75), at(30), at(60)}) ==
        std::vector<int>{at(75), at(30), at(75), at(30), at(75)});
}

TEST_CASE("Pen heights out of range, NaN, on a finished job or on a plotter that is not an EBB: --pos-up/--pos-down refused in one line, exit 1", "[ebb]") {
  test::TempDir t;
  const std::string svg = two_strokes(t);
  const std::vector<std::string> cmds{"export " + svg + " --profile axidraw-v3 -o " + t.file("x.ebb"),
                                      "plot " + svg + " --profile axidraw-v3 --port /dev/null", "pen down --port /dev/null"};
  for (const std::string& cmd : cmds) {
    for (const std::string bad : {" --pos-up 101", " --pos-down -1", " --pos-up nan", " --pos-down NaN"}) {
      auto r = test::run_cli(cmd + bad);
      INFO(cmd + bad << ": " << r.err);
      CHECK(r.exit_code == 1);
      CHECK(r.err.find(bad.substr(1, bad.find(' ', 1) - 1)) != std::string::npos);
      CHECK(test::count_lines(r.err) == 1);
    }
  }
  CHECK(!std::filesystem::exists(t.file("x.ebb")));
  auto g = test::run_cli("export " + svg + " --profile grbl-servo --pos-down 20 -o " + t.file("g.gcode"));
  CHECK(g.exit_code == 1);
  CHECK(g.err.find("profile grbl-servo is not one (protocol grbl") != std::string::npos);
  CHECK(test::count_lines(g.err) == 1);
  CHECK(!std::filesystem::exists(t.file("g.gcode")));
  auto pg = test::run_cli("plot " + svg + " --pos-up 70 --port /dev/null");  // the default profile, grbl-servo
  CHECK(pg.exit_code == 1);
  CHECK(pg.err.find("--pos-up sets an EiBotBoard") != std::string::npos);
  CHECK(test::count_lines(pg.err) == 1);
  REQUIRE(test::run_cli("export " + svg + " --profile axidraw-v3 -q -o " + t.file("done.ebb")).exit_code == 0);
  auto job = test::run_cli("plot " + t.file("done.ebb") + " --pos-up 70 --port /dev/null");
  CHECK(job.exit_code == 1);
  CHECK(job.err.find("finished job") != std::string::npos);
  CHECK(test::count_lines(job.err) == 1);
}

TEST_CASE("The ebb-moves option: lm or sm for an EBB export or plot, and anything else, another plotter or a finished job refused in one line", "[ebb]") {
  test::TempDir t;
  const std::string svg = two_strokes(t);
  REQUIRE(test::run_cli("export " + svg + " --profile axidraw-v3 --ebb-moves sm -q -o " + t.file("sm.ebb")).exit_code == 0);
  REQUIRE(test::run_cli("export " + svg + " --profile axidraw-v3 -q -o " + t.file("lm.ebb")).exit_code == 0);
  const std::string sm = test::read_file(t.file("sm.ebb")), lm = test::read_file(t.file("lm.ebb"));
  CHECK(sm.find("\nSM,") != std::string::npos);
  CHECK(sm.find("\nLM,") == std::string::npos);
  CHECK(lm.find("\nLM,") != std::string::npos);  // the default
  CHECK(lm.find("\nSM,") == std::string::npos);
  for (const std::string& cmd : {"export " + svg + " --profile axidraw-v3 --ebb-moves t3 -o " + t.file("x.ebb"),
                                "export " + svg + " --profile grbl-servo --ebb-moves sm -o " + t.file("x.gcode"),
                                "plot " + t.file("lm.ebb") + " --profile axidraw-v3 --ebb-moves sm --port /dev/null",
                                "plot --resume " + t.file("lm.ebb") + " --ebb-moves sm --port /dev/null"}) {
    auto r = test::run_cli(cmd);
    INFO(cmd << ": " << r.err);
    CHECK(r.exit_code != 0);
    CHECK(r.err.find("--ebb-moves") != std::string::npos);
    CHECK(test::count_lines(r.err) == 1);
  }
  CHECK(!std::filesystem::exists(t.file("x.ebb")));
  CHECK(!std::filesystem::exists(t.file("x.gcode")));
}
