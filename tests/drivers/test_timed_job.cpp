// The timed motion plan: grbl's planner and stepper (drivers/motion/grbl_motion) against
// hand-computed profiles, the job timer against the simulated grbl and HPGL plotter that
// run the same models over a pty, and the estimate the CLI reports from written lines.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <random>
#include <nlohmann/json.hpp>

#include "drivers/device/motion_setup.hpp"
#include "drivers/device/pen_rule.hpp"
#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "drivers/job/timed_job.hpp"
#include "drivers/motion/grbl_motion.hpp"
#include "drivers/stream/grbl/streamer.hpp"
#include "drivers/stream/hpgl/streamer.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "jobgen.hpp"
#include "sim/grbl_sim.hpp"
#include "sim/hpgl_sim.hpp"
#include "test_util.hpp"
#include "util/units.hpp"

using namespace stipplot;
using namespace stipplot::motion;

namespace {

GrblSettings servo_machine() {
  GrblSettings s;  // the validators' grbl-servo settings: 100 steps/mm, 9000 mm/min, 1000 mm/s^2
  return s;
}

// Runs the motion to rest, returning when the last block finished.
double run_to_rest(GrblMotion& m) {
  double end = 0;
  while (std::isfinite(m.next_event())) {
    const double t = m.next_event();
    m.advance(t);
    for (const auto& f : m.take_finished()) end = f.t;
  }
  return end;
}

}  // namespace

TEST_CASE("grbl dwell: whole 50 ms steps rounded up, as grbl's delay_sec counts them", "[motion][grbl]") {
  CHECK(grbl_dwell_seconds(0.15) == Approx(0.15));
  CHECK(grbl_dwell_seconds(0.05) == Approx(0.05));
  CHECK(grbl_dwell_seconds(0.12) == Approx(0.15));
  CHECK(grbl_dwell_seconds(0.01) == Approx(0.05));
  CHECK(grbl_dwell_seconds(0) == 0);
}

TEST_CASE("grbl motion: a rapid is a triangle at the per-axis acceleration, then the idle lock", "[motion][grbl]") {
  GrblMotion m(servo_machine());
  // 10 mm from rest to rest at 1000 mm/s^2 cannot reach 150 mm/s: vp = sqrt(a L) = 100 mm/s, 0.2 s.
  REQUIRE(m.plan({10, 0, 0}, 0, true, 1, 0));
  CHECK(m.next_event() == Approx(0.2).epsilon(1e-9));
  m.advance(0.2);
  REQUIRE(m.take_finished().size() == 1);
  // At rest the stepper notices one timer period later (the last 10 ms segment holds 5
  // steps: 2 ms) and then holds grbl for $1 = 25 ms.
  CHECK(m.busy());
  m.advance(0.2 + 0.002 + 0.025 - 1e-6);
  CHECK(m.busy());
  m.advance(0.2 + 0.002 + 0.025 + 1e-6);
  CHECK_FALSE(m.busy());
  CHECK(m.stops() == 1);
  // A move too small for one step makes no block (grbl drops it).
  CHECK_FALSE(m.plan({10.004, 0, 0}, 600, false, 2, 1));
  // Diagonal: each axis gives 1000 mm/s^2, so the move accelerates at 1000 * sqrt 2.
  GrblMotion d(servo_machine());
  REQUIRE(d.plan({10, 10, 0}, 0, true, 1, 0));
  const double L = std::sqrt(200.0), a = 1000 * std::sqrt(2.0);
  CHECK(run_to_rest(d) == Approx(2 * std::sqrt(L / a)).epsilon(1e-9));
}

TEST_CASE("grbl motion: junction speed from the per-axis acceleration along the junction vector", "[motion][grbl]") {
  GrblSettings s = servo_machine();
  s.accel_mm_s2 = {1000, 250, 1000};  // a slow Y axis
  GrblMotion m(s);
  REQUIRE(m.plan({20, 0, 0}, 3000, false, 1, 0));
  REQUIRE(m.plan({20, 20, 0}, 3000, false, 2, 0));
  // 90 degrees: sin(45) / (1 - sin 45); the junction vector (-1, 1)/sqrt 2 is limited by
  // Y: 250 * sqrt 2 along it (grbl's limit_value_by_axis_maximum).
  const double sh = std::sqrt(0.5);
  const double expect = 250 * std::sqrt(2.0) * 0.01 * sh / (1 - sh);
  REQUIRE(m.blocks().size() == 2);
  CHECK(m.blocks()[1].max_entry_sqr == Approx(expect));
  CHECK(m.blocks()[1].accel == Approx(250));  // the Y move accelerates at Y's limit
}

TEST_CASE("grbl motion: a block planned into an empty planner starts from rest", "[motion][grbl]") {
  GrblMotion m(servo_machine());
  REQUIRE(m.plan({10, 0, 0}, 0, true, 1, 0));
  const double end = run_to_rest(m);
  // The host was late: the next straight-on move starts from rest after the idle lock.
  m.advance(end + 0.1);
  REQUIRE(m.plan({20, 0, 0}, 0, true, 2, end + 0.1));
  CHECK(m.blocks().front().entry_sqr == 0);
  CHECK(m.starts_from_rest().size() == 2);
  // Sent in time (both in the planner), the same two moves blend into one 20 mm triangle.
  GrblMotion j(servo_machine());
  REQUIRE(j.plan({10, 0, 0}, 0, true, 1, 0));
  REQUIRE(j.plan({20, 0, 0}, 0, true, 2, 0));
  CHECK(run_to_rest(j) == Approx(2 * std::sqrt(20.0 / 1000)).epsilon(1e-9));
}

TEST_CASE("grbl motion: a feed hold decelerates and stops inside the block, resume finishes it", "[motion][grbl]") {
  GrblMotion m(servo_machine());
  REQUIRE(m.plan({100, 0, 0}, 3000, false, 1, 0));  // 50 mm/s
  m.advance(0.5);
  CHECK(m.speed() == Approx(50));
  m.hold(0.5);
  m.advance(0.6);  // 50 mm/s stops in 0.05 s and 1.25 mm
  CHECK(m.hold_complete());
  CHECK(m.position()[0] == Approx(0.05 * 0.5 * 50 + (0.5 - 0.05) * 50 + 1.25).margin(1e-6));
  m.resume(0.7);
  const double end = run_to_rest(m);
  CHECK(m.position()[0] == Approx(100));
  CHECK(end > 0.7);
}

TEST_CASE("the job timer: syncs wait for the stop and the idle lock, dwells in grbl's steps", "[motion][grbl][timing]") {
  io::Job job = io::parse_gcode_job("G21\nG90\nG0 X10\nM3 S1000\nG4 P0.15\nM5\nG4 P0.12\nG0 X20\n");
  io::GcodeLink instant;
  instant.baud = 0;
  const io::JobTiming t = io::time_gcode_job(job, servo_machine(), instant);
  // move 0.2 s, the stop noticed 2 ms later, $1 25 ms, dwell 0.15, dwell 0.12 -> 0.15, then
  // the second move starts one timer period late (2 ms) and takes 0.2 s.
  const double expect = 0.2 + 0.002 + 0.025 + 0.15 + 0.15 + 0.002 + 0.2;
  CHECK(t.total_s == Approx(expect).epsilon(1e-9));
  CHECK(t.stops == 2);
  REQUIRE(t.done_s.size() == job.lines.size());
  CHECK(t.done_s[2] == Approx(0.2));                 // the first move's block is done
  CHECK(t.done_s[3] == Approx(0.2 + 0.002 + 0.025));  // M3 ran once the machine stopped
  for (size_t i = 1; i < t.done_s.size(); ++i) CHECK(t.done_s[i] >= t.done_s[i - 1]);
  io::apply_timing(job, t);
  CHECK(io::seconds_after(job, 2) == Approx(expect - 0.2));
  CHECK(io::seconds_after(job, -1) == Approx(expect));
}

TEST_CASE("the job timer: character counting over a slow wire starves the planner", "[motion][grbl][timing]") {
  std::string g = "G21\nG90\n";
  for (int i = 1; i <= 40; ++i) g += "G1 X" + std::to_string(i * 0.5) + " Y0 F3000\n";
  io::Job job = io::parse_gcode_job(g);
  io::GcodeLink fast, slow;
  fast.baud = 0;
  slow.baud = 1200;  // 120 bytes a second: a 20-byte line every 0.17 s
  const double t_fast = io::time_gcode_job(job, servo_machine(), fast).total_s;
  const io::JobTiming t_slow = io::time_gcode_job(job, servo_machine(), slow);
  CHECK(t_fast < 1);
  size_t bytes = 0;
  for (const auto& l : job.lines) bytes += l.text.size() + 1;
  CHECK(t_slow.total_s > 10.0 * static_cast<double>(bytes) / 1200 * 0.95);  // the wire sets the pace
  CHECK(t_slow.stops > 30);  // and the machine stops at nearly every line
}

TEST_CASE("G-code words: numbers read as strtod reads them, bit for bit, without allocating", "[gcode][timing]") {
  // The lexer's fast path (at most 15 digits: one exact division) and its strtod fallback.
  std::mt19937_64 rng(7);
  std::vector<std::string> numbers = {"0",   "-0",  "+5",   "1.",   ".5",   "-.25", "+.5",  "12.345678",
                                      "1.2.3", "--5", "+-5", "-",   "+",    ".",    "0.1",  "123456789012345",
                                      "1234567890123456", "0.30000000000000004", "99999999999999999999",
                                      "1" + std::string(400, '0'), "0." + std::string(30, '0') + "1"};
  std::uniform_int_distribution<int> len(1, 19), digit(0, 9), point(0, 20);
  for (int k = 0; k < 20000; ++k) {
    std::string t = (k % 3 == 0) ? "-" : "";
    const int n = len(rng), at = point(rng);
    for (int j = 0; j < n; ++j) {
      if (j == at) t += '.';
      t += static_cast<char>('0' + digit(rng));
    }
    numbers.push_back(t);
  }
  size_t fast = 0;
  for (const std::string& t : numbers) {
    INFO(t);
    const double want = std::strtod(t.c_str(), nullptr);
    const double got = io::detail::gcode_number(t);
    CHECK(std::memcmp(&want, &got, sizeof want) == 0);  // the same bits, -0 included
    double v = 0;
    if (short_decimal(t, v)) {
      ++fast;
      CHECK(std::memcmp(&want, &v, sizeof want) == 0);
    }
  }
  CHECK(fast > numbers.size() / 2);  // the fast path was taken, not only strtod
  // The visitor and the vector agree, and a line with '$' or '%' has no words.
  for (const std::string line : {"G1 X12.5 Y-3 F3000", "g0x1y2", "G1 X1 2.5", "M3 S1000", "$H", "G1 X5 $H", "%", "G4 P0.15"}) {
    INFO(line);
    std::vector<io::GcodeWord> seen;
    io::for_each_gcode_word(line, [&](const io::GcodeWord& w) { seen.push_back(w); });
    const std::vector<io::GcodeWord> words = io::gcode_words(line);
    REQUIRE(seen.size() == words.size());
    for (size_t i = 0; i < seen.size(); ++i) {
      CHECK(seen[i].letter == words[i].letter);
      CHECK(seen[i].value == words[i].value);
    }
  }
  CHECK(io::gcode_words("G1 X5 $H").empty());
  CHECK(io::gcode_words("g0x1y2").size() == 3);
  CHECK(io::gcode_words("G1 X1 2.5")[1].value == 12.5);
  std::string scratch;
  CHECK(io::gcode_line_view("  G1 X5  ", scratch) == "G1 X5");
  CHECK(io::gcode_line_view("G1 X5 (note) Y2 ; more\r", scratch) == "G1 X5  Y2");
  CHECK(io::gcode_line_view("; only a comment", scratch).empty());
}

TEST_CASE("the job timer agrees with the simulated grbl, which runs the same motion over a pty", "[motion][grbl][timing][e2e][realtime]") {
  DeviceProfile prof = find_profile("grbl-servo");
  io::Job job = io::parse_gcode_job(testjob::gcode(testjob::random_strokes(31, 12, 6)), gcode_pen_rule(prof));
  sim::GrblSimConfig c = sim::grbl_sim_config(prof);
  c.speedup = 10;
  sim::GrblSim sim(c);
  io::PosixSerial port(sim.open_pty(), {});
  io::grbl::Streamer st(port, {});
  st.connect();
  REQUIRE(st.stream(job, 0, {}, nullptr).completed);
  REQUIRE(sim.wait_idle(30));
  io::GcodeLink instant;
  instant.baud = 0;
  const io::JobTiming t = io::time_gcode_job(job, grbl_settings_for(prof), instant);
  // The simulator's busy span: from the first move to the last thing done, less the time
  // it waited for data (the pty and this machine's load, magnified by the speed-up): the
  // timer's host keeps it fed.
  const double sim_s = sim.stats().plot_time() - sim.stats().starved_s;
  INFO("timer " << t.total_s - t.motion_start_s << " s, simulator " << sim_s << " s");
  CHECK(sim_s == Approx(t.total_s - t.motion_start_s).epsilon(0.01));
}

TEST_CASE("the HPGL timer agrees with the simulated plotter", "[motion][hpgl][timing][e2e][realtime]") {
  DeviceProfile prof = find_profile("hp7475a-a4");
  io::Job job = io::parse_hpgl_job(testjob::hpgl(testjob::random_strokes(32, 15, 6)));
  sim::HpglSimConfig c = sim::hpgl_sim_config(prof);
  c.speedup = 20;
  sim::HpglSim sim(c);
  io::PosixSerial port(sim.open_pty(), {});
  io::hpgl::Streamer st(port, io::hpgl::options_for(prof));
  st.connect();
  REQUIRE(st.stream(job, 0, {}, nullptr).completed);
  REQUIRE(sim.wait_idle(30));
  const io::JobTiming t = io::time_hpgl_job(job, hpgl_motion_for(prof));
  // The timer's host keeps the plotter fed; time the plotter waited for data (the pty
  // and this machine's load, 20x magnified) is not the plotter's.
  const double sim_s = sim.stats().plot_time() - sim.stats().starved_s;
  INFO("timer " << t.total_s << " s, simulator " << sim_s << " s");
  CHECK(sim_s == Approx(t.total_s).epsilon(0.02));
}

TEST_CASE("export's estimate is the timed plan of the lines it wrote, per layer and in total", "[cli][timing]") {
  test::TempDir t;
  for (const std::string profile : {"grbl-servo", "grbl-z", "hp7475a-a4"}) {
    const std::string out = t.file(profile == "hp7475a-a4" ? "f.hpgl" : "f.gcode");
    auto r = test::run_cli("export " + std::string(STIPPLOT_SOURCE_DIR) + "/examples/foreign.svg --profile " + profile +
                           " -o " + out + " --json");
    REQUIRE(r.exit_code == 0);
    const nlohmann::json plan = nlohmann::json::parse(r.out)["plan"];
    DeviceProfile prof = find_profile(profile);
    const std::string text = test::read_file(out);
    io::JobTiming timed;
    if (prof.protocol == Protocol::grbl) {
      io::GcodeLink link;
      link.baud = prof.serial.port.baud;
      timed = io::time_gcode_job(io::parse_gcode_job(text, gcode_pen_rule(prof)), grbl_settings_for(prof), link);
    } else {
      timed = io::time_hpgl_job(io::parse_hpgl_job(text), hpgl_motion_for(prof));
    }
    INFO(profile);
    CHECK(plan["total"]["seconds"].get<double>() == Approx(timed.total_s).epsilon(1e-9));
    double layers = 0;
    for (const auto& l : plan["layers"]) layers += l["seconds"].get<double>();
    CHECK(layers == Approx(timed.total_s).epsilon(0.02));  // the header lines belong to no layer
  }
}
