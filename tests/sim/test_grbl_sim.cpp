// The simulated grbl speaks grbl 1.1's protocol and keeps its timing model.
#include <catch2/catch.hpp>
#include <cmath>

#include "drivers/transport/transport.hpp"
#include "sim/grbl_sim.hpp"
#include "sim/hpgl_sim.hpp"
#include "sim/record.hpp"

using namespace stipplot;
using namespace stipplot::io;

namespace {
struct Talk {
  std::unique_ptr<Transport> t;
  LineReader r;
  explicit Talk(std::unique_ptr<Transport> tt) : t(std::move(tt)), r(*t) {}
  std::string line(int ms = 5000) { return r.expect_line(Millis(ms), "line"); }
  std::string send(const std::string& s) {
    t->write(s + "\n");
    return line();
  }
};
}  // namespace

TEST_CASE("sim grbl: banner, ok, errors, settings, status", "[sim][grbl]") {
  sim::GrblSimConfig c;
  c.speedup = 50;
  sim::GrblSim g(c);
  Talk k(g.connect_loopback());
  CHECK(k.line() == "Grbl 1.1h ['$' for help]");
  CHECK(k.send("G21 G90") == "ok");
  CHECK(k.send("G1 X10") == "error:22");   // no feed rate yet
  CHECK(k.send("G5 X1") == "error:20");    // unsupported
  CHECK(k.send("X") == "error:2");         // letter without a number
  CHECK(k.send("1X") == "error:1");
  CHECK(k.send(std::string(90, 'G').replace(0, 90, "G1X1") + std::string(86, '0')) == "error:11");  // over 80 chars
  CHECK(k.send("$Q") == "error:3");
  k.t->write("$$\n");
  bool saw110 = false;
  for (std::string l = k.line(); l != "ok"; l = k.line()) saw110 |= l.rfind("$110=", 0) == 0;
  CHECK(saw110);
  k.t->write("?");
  std::string st = k.line();
  CHECK(st.rfind("<Idle|MPos:0.000,0.000,0.000|Bf:15,128|FS:", 0) == 0);
}

TEST_CASE("sim grbl: a move takes its trapezoid's time, hold freezes it, Ctrl-X in motion alarms", "[sim][grbl]") {
  sim::GrblSimConfig c;
  c.speedup = 20;
  c.machine.accel_mm_s2 = {1000, 1000, 1000};
  c.machine.idle_lock_s = 0;  // the trapezoid alone
  sim::GrblSim g(c);
  Talk k(g.connect_loopback());
  k.line();
  // 100 mm at 50 mm/s with 1000 mm/s^2: 0.05 s up, 0.05 s down, 97.5 mm cruising: 2.05 s.
  CHECK(k.send("G1 X100 F3000") == "ok");
  REQUIRE(g.wait_idle(30));
  CHECK(g.stats().plot_time() == Approx(2.05).epsilon(0.01));
  // A short move cannot reach cruise: triangle, 2*sqrt(L/a) = 2*sqrt(0.001) s for 1 mm.
  double before = g.stats().busy_end;
  CHECK(k.send("G1 X101") == "ok");
  REQUIRE(g.wait_idle(30));
  CHECK(g.stats().busy_end - before >= 2 * std::sqrt(0.001) - 1e-6);
  // Hold during a long move: the position stops changing.
  CHECK(k.send("G1 X0 F600") == "ok");  // 10 s at 10 mm/s
  k.t->write("!");
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  k.t->write("?");
  std::string s1 = k.line();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  k.t->write("?");
  std::string s2 = k.line();
  CHECK(s1.rfind("<Hold:0|", 0) == 0);
  CHECK(s1.substr(0, s1.find("|Bf")) == s2.substr(0, s2.find("|Bf")));
  k.t->write("~");
  k.t->write("?");
  CHECK(k.line().rfind("<Run|", 0) == 0);
  k.t->write("\x18");
  CHECK(k.line() == "ALARM:3");
  CHECK(k.line() == "Grbl 1.1h ['$' for help]");
  CHECK(k.line().find("unlock") != std::string::npos);
  CHECK(k.send("G1 X5") == "error:9");  // locked
  CHECK(k.send("$X") == "[MSG:Caution: Unlocked]");
  CHECK(k.line() == "ok");
}

TEST_CASE("sim grbl: the receive buffer is 128 bytes, overfilling it loses bytes", "[sim][grbl]") {
  sim::GrblSimConfig c;
  c.speedup = 1;
  sim::GrblSim g(c);
  Talk k(g.connect_loopback());
  k.line();
  // 16 slow moves fill the planner; what follows piles up in the RX buffer.
  std::string burst;
  for (int i = 0; i < 40; ++i) burst += "G1 X" + std::to_string(i % 2 ? 0 : 100) + " F600\n";
  k.t->write(burst);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  CHECK(g.stats().rx_overflow > 0);
  k.t->write("\x18");
}

TEST_CASE("sim grbl: pen record from servo and Z, check mode moves nothing", "[sim][grbl]") {
  sim::GrblSimConfig c;
  c.speedup = 50;
  sim::GrblSim g(c);
  Talk k(g.connect_loopback());
  k.line();
  for (const char* l : {"G21 G90", "G0 X10 Y10", "M3 S30", "G1 X20 F3000", "M5", "G0 X30", "G1 Z-1 F600", "G1 Z1",
                        "$C", "M3 S30", "G1 X50 F3000", "M5"}) {
    if (std::string(l) == "$C") REQUIRE(g.wait_idle(30));  // '$' commands need an idle grbl (else error:8)
    std::string r = k.send(l);
    if (r.rfind("[MSG", 0) == 0) r = k.line();
    CHECK(r == "ok");
  }
  REQUIRE(g.wait_idle(30));
  auto rec = g.record();
  REQUIRE(rec.size() == 2);
  CHECK(rec[0] == Segment{10, 10, 20, 10, 1});
  CHECK(rec[1] == Segment{30, 10, 30, 10, 1});  // a Z touch
  k.t->write("?");
  CHECK(k.line().rfind("<Check|", 0) == 0);
}

TEST_CASE("sim HPGL: ESC.B, ESC.L, OE, and drawing", "[sim][hpgl]") {
  sim::HpglSimConfig c;
  c.speedup = 50;
  sim::HpglSim h(c);
  Talk k(h.connect_loopback());
  k.t->write("\x1b.L");
  CHECK(k.line() == "1024");
  k.t->write("IN;SP1;PU400,400;PD800,400;PU;");
  k.t->write("\x1b.B");
  int free = std::stoi(k.line());
  CHECK(free < 1024);
  REQUIRE(h.wait_idle(30));
  k.t->write("\x1b.B");
  CHECK(k.line() == "1024");
  k.t->write("XX;OE;");
  CHECK(k.line() == "1");
  auto rec = h.record();
  REQUIRE(rec.size() == 1);
  CHECK(rec[0] == Segment{400, 400, 800, 400, 1});
  Page p;
  auto d = sim::record_to_drawing(rec, p, 40);
  REQUIRE(d.layers.size() == 1);
  CHECK(d.layers[0].lines.at(0).pts.at(1).x == Approx(20));
}
