// stipplot pen on the EBB's own firmware (ebb_sim over a pty): the servo's positions set in
// percent as axicli sets them, and the pen raised, lowered, toggled and cycled; the judge
// is the firmware's event log (the servo's pulse width, the pen state).
#include <catch2/catch.hpp>

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

// The firmware log's SERVO pulse widths and PEN states, in order.
struct PenEvents {
  std::vector<int> pulses;
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
    } else if (ev == "PEN") {
      s >> a;
      e.pens.push_back(a);
    }
  }
  return e;
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
