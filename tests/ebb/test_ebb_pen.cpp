// stipplot pen on the EBB's own firmware (ebb_sim over a pty): the servo's positions set in
// percent as axicli sets them, and the pen raised, lowered, toggled and cycled; the judge
// is the firmware's event log (the servo's pulse width, the pen state).
#include <catch2/catch.hpp>

#include <algorithm>
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
