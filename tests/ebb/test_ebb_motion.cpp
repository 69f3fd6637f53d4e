// The EBB's profiles, job reader, SM slicing and firmware check, without the firmware.
#include <catch2/catch.hpp>
#include <functional>

#include <cmath>
#include <cstdlib>
#include <random>
#include <thread>

#include "drivers/device/profile.hpp"
#include "drivers/job/ebb_reader.hpp"
#include "drivers/job/timed_job.hpp"
#include "drivers/motion/ebb_motion.hpp"
#include "drivers/stream/ebb/streamer.hpp"
#include "drivers/transport/devices.hpp"
#include "drivers/transport/loopback.hpp"
#include "drivers/writers/ebb_writer.hpp"
#include "util/error.hpp"

using namespace stipplot;

TEST_CASE("AxiDraw profiles carry axidraw_conf's numbers and axicli's pen", "[ebb]") {
  const DeviceProfile v3 = find_profile("axidraw-v3");
  CHECK(v3.protocol == Protocol::ebb);
  CHECK(v3.machine.travel_x_mm == Approx(11.81 * 25.4).margin(0.01));
  CHECK(v3.machine.travel_y_mm == Approx(8.58 * 25.4).margin(0.01));
  CHECK(v3.ebb.steps_per_mm == 80);  // 2032 steps/inch
  CHECK(v3.motion.speed_down_mm_s == Approx(25 * 8.6979 / 110 * 25.4).epsilon(1e-3));
  CHECK(v3.motion.speed_up_mm_s == Approx(75 * 8.6979 / 110 * 25.4).epsilon(1e-3));
  const EbbPen pen = ebb_pen(v3.pen, v3.ebb);
  CHECK(pen.up == 20641);  // 9855 + 179.76 * 60
  CHECK(pen.down == 15248);
  CHECK(pen.rate_up == 1618);
  CHECK(pen.rate_down == 1079);
  CHECK(pen.raise_ms == 130);  // axicli pen_handling: ((2.69*30+45)^4 + (200*30/75)^4)^(1/4)
  CHECK(pen.lower_ms == 146);
  CHECK(v3.motion.pen_lift_s == Approx(0.130));
  CHECK(find_profile("axidraw-v3-a3").machine.travel_x_mm == Approx(16.93 * 25.4).margin(0.01));
  CHECK(find_profile("axidraw-minikit").machine.travel_y_mm == Approx(101.6));
}

TEST_CASE("NextDraw profiles carry nextdraw_conf's numbers and the brushless lift, iDraw ones its extension's", "[ebb]") {
  const DeviceProfile nd = find_profile("nextdraw-8511");
  CHECK(nd.protocol == Protocol::ebb);
  CHECK(nd.machine.travel_x_mm == Approx(11.81 * 25.4).margin(0.01));
  CHECK(nd.machine.travel_y_mm == Approx(8.58 * 25.4).margin(0.01));
  CHECK(nd.ebb.steps_per_mm == 80);
  CHECK(nd.motion.speed_down_mm_s == Approx(25 * 8.6979 / 100 * 25.4).epsilon(1e-3));
  CHECK(nd.motion.speed_up_mm_s == Approx(75 * 8.6979 / 100 * 25.4).epsilon(1e-3));
  // The S-curve's jerk (20000 x derate x 0.75^3 in/s^3) as the acceleration of the same time.
  for (const auto& [name, derate] : {std::pair{"nextdraw-8511", 1.0}, {"nextdraw-1117", 0.9}, {"nextdraw-2234", 0.6}})
    CHECK(find_profile(name).motion.accel_mm_s2 ==
          Approx(std::sqrt(25 * 8.6979 / 100 * 20000 * derate * 0.421875) / 2 * 25.4).epsilon(1e-3));
  CHECK(nd.pen.ebb_brushless);
  CHECK(pen_method_name(nd.pen) == "ebb-brushless");
  CHECK(nd.ebb.fifo_commands == 16);
  const EbbPen pen = ebb_pen(nd.pen, nd.ebb);
  CHECK(pen.up == 9720);  // 5400 + 72 * 60
  CHECK(pen.down == 8280);
  CHECK(pen.rate_up == 231);  // 7200 * 0.03 / 70 * 75
  CHECK(pen.rate_down == 154);
  CHECK(pen.raise_ms == 45);  // ((1.28*20+20)^4 + (70*20/75)^4)^(1/4)
  CHECK(pen.lower_ms == 47);
  CHECK(ebb_servo_setup(pen).back() == "SC,8,1");
  CHECK(ebb_pen_command(pen, true) == "SP,0,47,2");
  CHECK(ebb_pen_command(pen, false) == "SP,1,45,2");
  CHECK(find_profile("nextdraw-1117").machine.travel_x_mm == Approx(16.93 * 25.4).margin(0.01));
  CHECK(find_profile("nextdraw-2234").machine.travel_y_mm == Approx(23.39 * 25.4).margin(0.01));
  const DeviceProfile id = find_profile("idraw-a4");
  CHECK(!id.pen.ebb_brushless);
  CHECK(id.ebb.steps_per_mm == 100);  // DPI_16X 2540
  CHECK(id.motion.speed_down_mm_s == Approx(25 * 24950.0 / 110 / (2540 * std::sqrt(2.0)) * 25.4).epsilon(1e-3));
  const EbbPen ip = ebb_pen(id.pen, id.ebb);
  CHECK(ip.up == 11600);  // 7500 + 205 * 20: iDraw's up is below its down
  CHECK(ip.down == 15700);
  CHECK(ip.rate_up == 750);  // idraw.py: 5 * 150 %/s
  CHECK(ip.raise_ms == 133);  // 1000 * 20 / 150
  CHECK(ip.lower_ms == 133);
  CHECK(ebb_pen_command(ip, false) == "SP,1,133");
  CHECK(ebb_servo_setup(ip).size() == 4);
  CHECK(find_profile("idraw-a3").machine.travel_x_mm == 420);
}

namespace {
// An EBB profile whose pen-up speed steps a motor past 25 kHz (speed_up_mm_s = 400).
std::string fast_profile_text() {
  return R"(name = "fast"
description = "x"
protocol = "ebb"
[machine]
travel_x_mm = 300
travel_y_mm = 200
origin = "top-left"
x_sign = 1
y_sign = 1
origin_offset_x_mm = 0
origin_offset_y_mm = 0
resolution_mm = 0.0125
[motion]
speed_down_mm_s = 50
speed_up_mm_s = 400
accel_mm_s2 = 700
junction_deviation_mm = 0.02
lookahead_blocks = 64
[pen]
method = "ebb-servo"
count = 1
pos_up_pct = 60
pos_down_pct = 30
rate_raise_pct = 75
rate_lower_pct = 50
delay_up_ms = 0
delay_down_ms = 0
dot_dwell_s = 0
[ebb]
steps_per_mm = 80
servo_min = 9855
servo_max = 27831
servo_sweep_ms = 200
servo_move_min_ms = 45
servo_move_slope_ms = 2.69
servo_pwm_period = 0.24
time_slice_ms = 25
fifo_commands = 32
[serial]
baud = 115200
flow_control = "none"
rx_buffer_bytes = 64
newline = false
)";
}
}  // namespace

TEST_CASE("An EBB profile refuses speeds past the firmware's step rate", "[ebb]") {
  std::string text = fast_profile_text();
  REQUIRE_THROWS_WITH(parse_profile(text, "fast.toml"), Catch::Contains("25 kHz"));
  text.replace(text.find("speed_up_mm_s = 400"), 19, "speed_up_mm_s = 150");
  CHECK(parse_profile(text, "ok.toml").motion.pen_drop_s == Approx(0.146));
  text.replace(text.find("ebb-servo"), 9, "ebb-brushless");
  CHECK(parse_profile(text, "nb.toml").pen.ebb_brushless);
  text.replace(text.find("ebb-brushless"), 13, "ebb-solenoid");
  CHECK_THROWS_WITH(parse_profile(text, "bad.toml"), Catch::Contains("pen.method must be one of ebb-servo|ebb-brushless"));
}

namespace {
// A zigzag of 400 long and very short segments: rounding must not accumulate over them.
std::vector<Vec2> zigzag() {
  std::vector<Vec2> pts{{0, 0}};
  for (int i = 0; i < 400; ++i) pts.push_back({pts.back().x + (i % 3 == 0 ? 0.013 : 1.7), pts.back().y + (i % 2 ? 0.9 : -0.4)});
  return pts;
}
}  // namespace

TEST_CASE("SM slices end exactly on the plan's step positions within the firmware's rate", "[ebb]") {
  const DeviceProfile p = find_profile("axidraw-v3");
  const motion::EbbGeometry g{80};
  const std::vector<Vec2> pts = zigzag();
  std::vector<motion::MotionBlock> blocks;
  const double planned = motion::polyline_seconds(pts, p.motion.speed_down_mm_s, p.motion, &blocks);
  motion::MotorSteps at{0, 0};
  int64_t clock = 0;
  std::vector<motion::EbbMove> moves;
  motion::slice_blocks(blocks, g, p.motion.accel_mm_s2, 25, at, clock, moves);
  int64_t m1 = 0, m2 = 0, ms = 0;
  for (const auto& m : moves) {
    REQUIRE(motion::ebb_move_ok(m));
    REQUIRE(m.ms <= 25);
    m1 += m.s1, m2 += m.s2, ms += m.ms;
  }
  CHECK(motion::MotorSteps{m1, m2} == g.steps(pts.back()));
  CHECK(at == g.steps(pts.back()));
  CHECK(ms == clock);
  CHECK(static_cast<double>(ms) / 1000 == Approx(planned).epsilon(0.01));
  const Vec2 end = g.mm(at);
  CHECK(std::hypot(end.x - pts.back().x, end.y - pts.back().y) <= 0.5 * std::sqrt(2.0) / 80 + 1e-12);
}

namespace {

// The firmware's LM arithmetic for one motor, tick by tick as ebb.c's ISR does it with
// 32-bit registers (accumulators cleared: 0, or 2^31 - 1 when the first rate is negative):
// the tick of the last of `steps` steps and the steps' signed sum; 0 ticks if it runs past
// `limit` ticks.
std::pair<int64_t, int64_t> isr_lm(int64_t rate, int64_t steps, int64_t accel, int64_t limit) {
  if (steps < 0) rate = -rate, steps = -steps, accel = -accel;  // the legacy form
  int32_t r = static_cast<int32_t>(rate - accel / 2);
  const int32_t a = static_cast<int32_t>(accel);
  uint32_t acc = static_cast<int64_t>(r) + a < 0 ? 0x7FFFFFFFu : 0;
  int64_t pos = 0, left = steps;
  for (int64_t tick = 1; tick <= limit; ++tick) {
    r = static_cast<int32_t>(static_cast<uint32_t>(r) + static_cast<uint32_t>(a));
    acc += static_cast<uint32_t>(r);
    if (acc & 0x80000000u) {
      acc &= 0x7FFFFFFFu;
      pos += r < 0 ? -1 : 1;
      if (--left == 0) return {tick, pos};
    }
  }
  return {0, pos};
}

}  // namespace

TEST_CASE("LM time: lm_motor_ticks is the firmware's ISR arithmetic, tick for tick", "[ebb]") {
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int64_t> steps(1, 400), ticks(1, 6000);
  std::uniform_real_distribution<double> share(0, 2);
  int checked = 0;
  for (int i = 0; i < 3000; ++i) {
    const int64_t s = steps(rng) * (i % 2 ? -1 : 1), n = ticks(rng);
    const double w0 = share(rng);
    const auto m = motion::lm_phase(s, 0, n, w0, 2 - w0);
    if (!m) continue;  // more steps than ticks
    const int64_t t = motion::lm_ticks(*m);
    const auto [isr_t, isr_pos] = isr_lm(m->r1, m->s1, m->a1, 2 * t + 1000);
    INFO(motion::ebb_command(*m));
    REQUIRE(isr_t == t);
    REQUIRE(isr_pos == s);  // every step the way it was asked: no reversal
    ++checked;
  }
  CHECK(checked > 1000);
}

TEST_CASE("LM phases land exactly on the plan's rounded step positions, in the plan's time", "[ebb]") {
  const DeviceProfile p = find_profile("axidraw-v3");
  const motion::EbbGeometry g{80};
  const std::vector<Vec2> pts = zigzag();  // phases of 0 and 1 step occur
  std::vector<motion::MotionBlock> blocks;
  const double planned = motion::polyline_seconds(pts, p.motion.speed_down_mm_s, p.motion, &blocks);
  motion::MotorSteps at{0, 0};
  int64_t clock = 0;
  std::vector<motion::EbbMove> moves;
  // Block by block: after each block's phases the motors stand on its end, rounded.
  size_t lms = 0;
  for (const motion::MotionBlock& b : blocks) {
    const size_t before = moves.size();
    motion::lm_blocks({b}, g, p.motion.accel_mm_s2, at, clock, moves);
    REQUIRE(moves.size() - before <= 3);  // accelerate, cruise, decelerate at most
    REQUIRE(at == g.steps(b.to));
  }
  int64_t m1 = 0, m2 = 0, ticks = 0;
  for (const auto& m : moves) {
    if (m.lm) {
      INFO(motion::ebb_command(m));
      REQUIRE(motion::lm_ok(m));
      ticks += motion::lm_ticks(m);
      ++lms;
    } else {
      REQUIRE(motion::ebb_move_ok(m));
      ticks += 25 * m.ms;
    }
    m1 += m.s1, m2 += m.s2;
  }
  CHECK(lms == moves.size());  // no phase needed an SM here
  CHECK(motion::MotorSteps{m1, m2} == g.steps(pts.back()));
  CHECK(ticks == clock);
  CHECK(static_cast<double>(ticks) / 25000 == Approx(planned).epsilon(0.01));
  // The same chain at once (lm_blocks is what polyline_moves does for LM) and its clock.
  motion::MotorSteps at2{0, 0};
  int64_t clock2 = 0;
  std::vector<motion::EbbMove> whole;
  motion::polyline_moves(pts, p.motion.speed_down_mm_s, p.motion, g, {}, at2, clock2, blocks, whole);
  CHECK(at2 == g.steps(pts.back()));
  CHECK(static_cast<double>(clock2) / 25000 == Approx(planned).epsilon(0.01));
  // A phase of no whole step gives its time to the next; a tiny move from rest is one LM.
  motion::MotorSteps at3{0, 0};
  int64_t clock3 = 0;
  std::vector<motion::EbbMove> tiny;
  motion::polyline_moves({{0, 0}, {0.0126, 0}}, 50, p.motion, g, {}, at3, clock3, blocks, tiny);
  CHECK(at3 == motion::MotorSteps{1, 1});
  REQUIRE(!tiny.empty());
  CHECK(tiny.size() <= 2);
  for (const auto& m : tiny) CHECK(motion::lm_ok(m));
}

TEST_CASE("EBB profile key [ebb] moves: lm by default, sm on request, anything else refused", "[ebb]") {
  CHECK(find_profile("axidraw-v3").ebb.moves == motion::EbbMoveKind::lm);
  std::string text = fast_profile_text();
  text.replace(text.find("speed_up_mm_s = 400"), 19, "speed_up_mm_s = 150");
  CHECK(parse_profile(text, "ok.toml").ebb.moves == motion::EbbMoveKind::lm);
  text.replace(text.find("fifo_commands"), 0, "moves = \"sm\"\n");
  CHECK(parse_profile(text, "sm.toml").ebb.moves == motion::EbbMoveKind::sm);
  text.replace(text.find("moves = \"sm\""), 12, "moves = \"t3\"");
  CHECK_THROWS_WITH(parse_profile(text, "bad.toml"), Catch::Contains("ebb.moves must be one of lm|sm"));
}

TEST_CASE("EBB job reader tracks motors, pen and the firmware's time", "[ebb]") {
  const io::Job job = io::parse_ebb_job("EM,1,1\nSP,1,130\nSM,25,160,0\n# pause: Change pen: pen 2\nSP,0,146\nSM,10,0,80\n", 80);
  REQUIRE(job.lines.size() == 6);
  CHECK(job.lines[2].x == Approx(1.0));
  CHECK(job.lines[2].y == Approx(1.0));
  CHECK(job.lines[3].host_only);
  CHECK(job.lines[3].pause);
  CHECK(job.lines[4].pen_down);
  CHECK(job.lines[5].x == Approx(1.5));
  CHECK(job.lines[5].y == Approx(0.5));
  const io::JobTiming t = io::time_ebb_job(job);
  CHECK(t.total_s == Approx(0.311));
  CHECK(t.done_s[2] == Approx(0.155));
  CHECK_THROWS_WITH(io::parse_ebb_job("LM,1,2,3\n", 80), Catch::Contains("LM takes a rate, steps and accel"));
  CHECK_THROWS_WITH(io::parse_ebb_job("XM,1,2,3\n", 80), Catch::Contains("only SM, LM, SP, EM, SC and CU"));
  // An LM whose rate reaches 0 before its last step would stall (or, on 3.x, reverse).
  CHECK_THROWS_WITH(io::parse_ebb_job("LM,1000,5,-10,0,0,0,3\n", 80), Catch::Contains("not stalling or reversing"));
  CHECK_THROWS_WITH(io::parse_ebb_job("LM,0,0,0,0,0,0\n", 80), Catch::Contains("an LM must move"));
  CHECK_THROWS_WITH(io::parse_ebb_job("SM,1,26,0\n", 80), Catch::Contains("25 per ms"));
  CHECK_THROWS_WITH(io::parse_ebb_job("SM,5,x,0\n", 80), Catch::Contains("line 1"));
  // Found by the fuzzer: a step count past strtoll's range saturated, passed the rate check
  // (llabs of the smallest long long) and overflowed the step sums.
  CHECK_THROWS_WITH(io::parse_ebb_job("SM,21,-77777777777777777777777777,0\n", 80), Catch::Contains("out of range"));
  CHECK_THROWS_WITH(io::parse_ebb_job("SM,21,0,9223372036854775807\n", 80), Catch::Contains("out of range"));
}

namespace {
// A board on the pipe's far end: each command (up to its '\r') is recorded in `heard` as
// "CMD;" and answered with answer(cmd), until the host has been silent for 2 s.
std::thread fake_board(std::shared_ptr<io::PipeEnd> board, std::function<std::string(const std::string&)> answer,
                       std::string& heard) {
  return std::thread([board, answer, &heard] {
    char buf[256];
    std::string in;
    for (;;) {
      const long n = board->read(buf, sizeof buf, std::chrono::milliseconds(2000));
      if (n <= 0) return;
      in.append(buf, static_cast<size_t>(n));
      for (size_t eol; (eol = in.find('\r')) != std::string::npos; in.erase(0, eol + 1)) {
        const std::string cmd = in.substr(0, eol);
        heard += cmd + ";";
        board->write(answer(cmd));
      }
    }
  });
}
}  // namespace

TEST_CASE("An LM job is refused in one line on EBB firmware before 2.7, before anything moves", "[ebb]") {
  auto [host, board] = io::make_pipe();
  // A 2.6 board: it answers V, and the test reads whatever else the host sends.
  std::string heard;
  std::thread fw = fake_board(
      board, [](const std::string& cmd) { return cmd == "V" ? "EBBv13_and_above EB Firmware Version 2.6.5\r\n" : "OK\r\n"; },
      heard);
  io::LoopbackTransport t(host);
  io::ebb::Streamer s(t, io::ebb::Options{});
  s.connect();
  const io::Job job = io::parse_ebb_job("EM,1,1\nSP,1,130\nLM,1000000,100,0,0,0,0,3\n", 80);
  CHECK_THROWS_WITH(s.stream(job, 0, {}, nullptr), Catch::Contains("2.7 or later") && Catch::Contains("moves = \"sm\""));
  t.close();
  fw.join();
  CHECK(heard == "V;");  // nothing of the job was sent
}

TEST_CASE("A V answer's tail left on the line by a dropped link is not taken for the board's answer", "[ebb]") {
  // The link came back while the board answered a dead host's V: the host's drain took the
  // head, "Version 3.0.2" is what is left when its own V goes out (a CI run saw it).
  auto [host, board] = io::make_pipe();
  std::string heard;
  int vs = 0;
  std::thread fw = fake_board(
      board,
      [&vs](const std::string& cmd) -> std::string {
        if (cmd != "V") return "OK\r\n";
        return vs++ == 0 ? "Version 3.0.2\r\n" : "EBBv13_and_above EB Firmware Version 3.0.2\r\n";
      },
      heard);
  io::LoopbackTransport t(host);
  io::ebb::Streamer s(t, io::ebb::Options{});
  REQUIRE_NOTHROW(s.connect());
  t.close();
  fw.join();
  CHECK(heard.rfind("V;V;", 0) == 0);
}

TEST_CASE("EBB firmware versions: 2.5 to 3.x, and what is not an EBB", "[ebb]") {
  const auto v3 = io::ebb::parse_firmware("EBBv13_and_above EB Firmware Version 3.0.2");
  CHECK(v3.major == 3);
  CHECK(v3.patch == 2);
  CHECK(io::ebb::parse_firmware("EBBv13_and_above EB Firmware Version 2.8.1").minor == 8);
  CHECK_THROWS_WITH(io::ebb::parse_firmware("Grbl 1.1h ['$' for help]"), Catch::Contains("does not answer V as an EiBotBoard"));
  CHECK_THROWS_WITH(io::ebb::parse_firmware("EBBv13_and_above EB Firmware Version 2.4.1"), Catch::Contains("not supported"));
  CHECK_THROWS_WITH(io::ebb::parse_firmware("EBBv13_and_above EB Firmware Version 4.0.0"), Catch::Contains("not supported"));
}

TEST_CASE("stipplot devices names an EiBotBoard by its USB id", "[ebb]") {
  io::DeviceList d;
  io::SerialPortInfo p;
  p.name = "/dev/ttyACM0";
  p.transport = "usb";
  p.vid = 0x04d8;
  p.pid = 0xfd92;
  p.product = "EiBotBoard";
  d.serial.push_back(p);
  const std::string s = io::format_devices(d);
  CHECK(s.find("04d8:fd92") != std::string::npos);
  CHECK(s.find("axidraw-v3") != std::string::npos);
  CHECK(io::choose_port(d) == "/dev/ttyACM0");
}
