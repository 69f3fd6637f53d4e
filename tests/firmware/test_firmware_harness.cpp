// The firmware harness itself: its log reader on canned grbl_avr output, then the real
// firmware driven by the harness as the host (no stipplot code involved), checking that
// what the logs say matches what was sent and grbl's own kinematics.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <thread>

#include "firmware/grbl_firmware.hpp"
#include "firmware/job_compare.hpp"

using namespace firmware;

namespace {

// A servo job as grbl_avr logs it, at 1 step a mm: a rapid to 3,3, the pen down, a line
// to 6,3, the pen up, and a move to 6,5 cut by a power cut after its first step.
const char* kLog =
    "# grbl_avr log: t = simulated seconds since power-on\n"
    "P 1.0000000 XY 1 1 0\n"
    "P 1.0010000 XY 2 2 0\n"
    "P 1.0020000 XY 3 3 0\n"
    "M 1.2000000 duty=1.0000 pwm=1 ocr2a=255 pb3=1 pb5=0 hz=976.6 pulse_us=1024.0\n"
    "P 1.3000000 X 4 3 0\n"
    "P 1.3010000 X 5 3 0\n"
    "P 1.3020000 X 6 3 0\n"
    "M 1.5000000 duty=0.0000 pwm=0 ocr2a=255 pb3=0 pb5=0 hz=976.6 pulse_us=0.0\n"
    "P 1.6000000 Y 6 4 0\n"
    "P 1.60";  // cut mid-line: the log is read while grbl_avr writes it

struct Transcript {
  std::vector<HostLine> lines;
  std::vector<SessionEvent> events;
  std::vector<DeviceLine> device;
  void reset() {
    device.push_back({"Grbl 1.1h ['$' for help]"});
    events.push_back({SessionEvent::Kind::Reset, 0, device.size() - 1});
  }
  void said(const std::string& text) { device.push_back({text}); }
  void ok(const std::string& text) {
    HostLine h;
    h.text = text;
    h.reply = HostLine::Reply::Ok;
    lines.push_back(h);
    events.push_back({SessionEvent::Kind::Line, lines.size() - 1});
  }
};

MachineSettings one_step_a_mm() { return MachineSettings::parse("$100=1\n$101=1\n$102=1\n$120=1000\n$121=1000\n$122=1000\n"); }

}  // namespace

TEST_CASE("firmware logs: steps and pen changes with their simulated times", "[firmware-logs]") {
  const StepLog log = parse_step_log(kLog);
  REQUIRE(log.steps.size() == 7);
  CHECK(log.steps[2].pos == Steps{3, 3, 0});
  CHECK(log.steps[3].t == Approx(1.3));
  REQUIRE(log.spindle.size() == 2);
  CHECK(log.spindle[0].duty == 1.0);
  CHECK(log.spindle[0].steps_before == 3);
  CHECK(log.spindle[1].steps_before == 6);
  CHECK_FALSE(log.ended);
  CHECK(parse_step_log("E 2.5000000 6 4 0\n").ended);
}

TEST_CASE("firmware logs: the step log walked along the answered lines gives each block's run and the marks",
          "[firmware-logs]") {
  Transcript tr;
  tr.reset();
  for (const char* l : {"G21", "G90", "G0 X3 Y3", "M3 S1000", "G1 X6 Y3 F3000", "M5", "G1 X6 Y5"}) tr.ok(l);
  FirmwareRecord rec;
  rec.settings = one_step_a_mm();
  rec.lines = tr.lines;
  rec.sessions.push_back(build_session(parse_step_log(kLog), tr.lines, tr.events, rec.settings));
  const SessionRecord& s = rec.sessions[0];
  INFO(describe(s, rec.settings));
  REQUIRE(s.blocks.size() == 3);
  CHECK(s.blocks[0].run == ExecutedBlock::Run::Complete);
  CHECK(s.blocks[0].duty == 0);
  CHECK(s.blocks[1].run == ExecutedBlock::Run::Complete);
  CHECK(s.blocks[1].duty == 1);
  CHECK(s.blocks[2].run == ExecutedBlock::Run::Partial);
  CHECK(s.blocks[2].stop == Steps{6, 4, 0});
  CHECK(s.problems.empty());
  // The pen change between them made the machine stop: rests after both blocks.
  CHECK(s.blocks[0].rest_after);
  CHECK(s.blocks[0].t_end == Approx(1.002 + std::sqrt(0.002)));  // a diagonal step: sqrt(2) mm at sqrt(2) x 1000 mm/s^2
  CHECK(s.blocks[1].t_start == Approx(1.3 - std::sqrt(2.0 / 1000)));
  const Interpretation in = interpret(rec, PenRule::servo());
  CHECK(in.inconsistencies.empty());
  REQUIRE(in.marks.size() == 1);
  CHECK(in.marks[0].kind == Mark::Kind::Segment);
  CHECK(in.marks[0].b == Steps{6, 3, 0});
  CHECK(in.pen_down_mm == Approx(3));
  CHECK(in.rests_at_sync == 2);
  CHECK(in.rests_starved == 0);
}

TEST_CASE("firmware logs: a reset in mid-stroke ends the block where the status reports place it, and steps no block explains are named",
          "[firmware-logs]") {
  const char* log =
      "M 0.5000000 duty=1.0000 pwm=1 ocr2a=255 pb3=1 pb5=0 hz=976.6 pulse_us=1024.0\n"
      "P 1.0000000 X 1 0 0\n"
      "P 1.0010000 X 2 0 0\n"
      "M 1.0015000 duty=0.0000 pwm=0 ocr2a=255 pb3=0 pb5=0 hz=976.6 pulse_us=0.0\n"  // the reset stops the spindle
      "P 2.0000000 X 1 0 0\n"  // after the reset: a pen-up move back
      "E 3.0000000 1 0 0\n";
  Transcript tr;
  tr.reset();
  for (const char* l : {"G21", "G90", "M3 S1000", "G1 X5 F3000"}) tr.ok(l);
  tr.said("<Run|MPos:1.000,0.000,0.000|Bf:15,128>");
  tr.reset();
  tr.said("<Idle|MPos:2.000,0.000,0.000|Bf:15,128>");  // where the reset left it
  tr.ok("G0 X1");
  FirmwareRecord rec;
  rec.settings = one_step_a_mm();
  rec.lines = tr.lines;
  rec.device = tr.device;
  rec.sessions.push_back(build_session(parse_step_log(log), tr.lines, tr.events, rec.settings, tr.device));
  const SessionRecord& s = rec.sessions[0];
  INFO(describe(s, rec.settings));
  REQUIRE(s.blocks.size() == 2);
  CHECK(s.blocks[0].run == ExecutedBlock::Run::Partial);
  CHECK(s.blocks[0].stop == Steps{2, 0, 0});
  CHECK(s.blocks[1].start == Steps{2, 0, 0});
  CHECK(s.blocks[1].run == ExecutedBlock::Run::Complete);
  CHECK(s.blocks[1].epoch == 1);
  const Interpretation in = interpret(rec, PenRule::servo());
  CHECK(in.inconsistencies.empty());
  REQUIRE(in.marks.size() == 1);
  CHECK(in.marks[0].kind == Mark::Kind::Partial);
  // Without the reset's line the steps after it follow nothing that grbl was sent.
  Transcript short_tr;
  short_tr.reset();
  for (const char* l : {"G21", "G90", "M3 S1000", "G1 X5 F3000"}) short_tr.ok(l);
  const SessionRecord t = build_session(parse_step_log(log), short_tr.lines, short_tr.events, rec.settings, short_tr.device);
  REQUIRE(t.problems.size() == 1);
  CHECK(t.problems[0].find("1 steps") != std::string::npos);
}

TEST_CASE("firmware model: grbl's view of a servo and a Z-pen job", "[firmware-logs]") {
  MachineSettings s = MachineSettings::parse("$100=100\n$101=100\n$102=100\n");
  const std::string servo = "G21 G90\nM5\nG0 X10 Y10\nM3 S1000\nG4 P0.15\nG1 X20 Y10 F3000\nG1 X20 Y10.004\nM5\n"
                            "G0 X5 Y5\nM3 S1000\nG4 P0.1\nM5\nG0 X0 Y0 ; home\n";
  auto m = expected_marks(servo, s, PenRule::servo());
  REQUIRE(m.size() == 2);  // the 0.004 mm move is no block: below one step
  CHECK(m[0].kind == Mark::Kind::Segment);
  CHECK(m[0].a == Steps{1000, 1000, 0});
  CHECK(m[0].b == Steps{2000, 1000, 0});
  CHECK(m[1].kind == Mark::Kind::Dot);
  CHECK(m[1].a == Steps{500, 500, 0});
  const std::string z = "G21\nG90\nG0 Z3\nG0 X10 Y-10\nG1 Z0 F1200\nG1 X20 F2400\nG0 Z3\nG0 X5 Y-5\nG1 Z0\nG0 Z3\n";
  auto mz = expected_marks(z, s, PenRule::z_axis(1.5));
  REQUIRE(mz.size() == 2);
  CHECK(mz[0].b == Steps{2000, -1000, 0});
  CHECK(mz[1].kind == Mark::Kind::Dot);
  CHECK_THROWS_WITH(expected_marks("G2 X1 Y1 I1\n", s, PenRule::servo()), Catch::Contains("not modelled"));
  auto same = compare_marks(m, {m[1], m[0], m[0]});
  CHECK(same.doubled == 1);
  CHECK(same.lost == 0);
  auto less = compare_marks(m, {m[1]});
  CHECK(less.lost == 1);
  // A stroke cut by a power loss at x = 16 and resumed from a status report's x = 14: two
  // pieces, neither the job's mark, that draw it on paper. Resumed from x = 17 instead,
  // x 16-17 stays bare; a piece off the stroke's line covers nothing.
  const Mark cut{Mark::Kind::Partial, {1000, 1000, 0}, {1600, 1000, 0}};
  const Mark rest{Mark::Kind::Segment, {1400, 1001, 0}, {2000, 1000, 0}};
  auto split = compare_marks(m, {m[1], cut, rest});
  CHECK(split.lost == 1);
  CHECK(bare_on_paper(split.lost_marks, {m[1], cut, rest}).empty());
  const Mark late{Mark::Kind::Segment, {1700, 1000, 0}, {2000, 1000, 0}};
  CHECK(bare_on_paper(split.lost_marks, {cut, late}).size() == 1);
  const Mark beside{Mark::Kind::Segment, {1400, 1010, 0}, {2000, 1010, 0}};
  CHECK(bare_on_paper(split.lost_marks, {cut, beside}).size() == 1);
  CHECK(bare_on_paper({m[1]}, {cut, rest}).size() == 1);  // a dot is a dot
}

TEST_CASE("grbl firmware: settings, a job sent line by line, and what the logs prove", "[firmware]") {
  GrblFirmware fw("grbl-servo");
  REQUIRE(fw.port().rfind("/dev/pts/", 0) == 0);
  auto dump = fw.command("$$");
  CHECK(std::find(dump.begin(), dump.end(), "$110=9000.000") != dump.end());
  CHECK(std::find(dump.begin(), dump.end(), "$120=1000.000") != dump.end());
  const std::string job =
      "G21\nG90\nM5\nG0 X10 Y10\nM3 S1000\nG4 P0.15\nG1 X60 Y10 F3000\nG1 X60 Y30\nM5\nG4 P0.15\n"
      "G0 X50 Y50\nM3 S1000\nG4 P0.15\nM5\nG4 P0.15\nG0 X0 Y0\n";
  for (const std::string& reply : fw.stream(gcode_lines(job))) REQUIRE(reply == "ok");
  REQUIRE(fw.wait_idle(30));
  FirmwareRecord rec = fw.record();
  REQUIRE(rec.sessions.size() == 1);
  const SessionRecord& s = rec.sessions[0];
  REQUIRE(s.blocks.size() == 5);
  for (const auto& b : s.blocks) CHECK(b.run == ExecutedBlock::Run::Complete);
  JobCheck jc = check_job(job, rec, PenRule::servo());
  INFO(describe(s, rec.settings));
  INFO(jc.marks.summary());
  CHECK(s.rx_overruns == 0);
  INFO(explain(jc, rec.settings));
  CHECK(jc.firmware.inconsistencies.empty());
  CHECK(jc.marks.exact());
  CHECK(jc.marks.expected_dots == 1);
  CHECK(jc.marks.drawn_segments == 2);
  // grbl's kinematics: a move of L mm from rest to rest at 50 mm/s, 1000 mm/s^2 takes L/v + v/a.
  const ExecutedBlock& line = s.blocks[1];
  CHECK(line.rest_after == false);  // the next move was already planned: a corner, not a stop
  const ExecutedBlock& corner = s.blocks[2];
  REQUIRE(line.t_start > 0);
  REQUIRE(corner.t_end > 0);
  double drawn = corner.t_end - line.t_start;
  // Both moves as one 70 mm trapezoid give a lower bound; the corner (90 degrees,
  // junction deviation 0.01) nearly stops: at most the two moves' rest-to-rest times.
  CHECK(drawn > 70.0 / 50 + 50.0 / 1000 - 0.01);
  CHECK(drawn < 50.0 / 50 + 50.0 / 1000 + 20.0 / 50 + 50.0 / 1000 + 0.01);
  // Pen changes make grbl empty its planner: every rest is at one.
  CHECK(jc.firmware.rests_starved == 0);
  CHECK(jc.firmware.rests_at_sync >= 3);
  CHECK(firmware_plot_seconds(rec, PenRule::servo()) > drawn);
  WARN(describe(s, rec.settings));
}

TEST_CASE("grbl firmware: a power cut mid-move, and power on again", "[firmware]") {
  GrblFirmware fw("grbl-servo");
  const std::string job = "G21\nG90\nM3 S1000\nG1 X100 F3000\nG1 X100 Y1\n";
  for (const std::string& l : gcode_lines(job)) REQUIRE(fw.command(l).back() == "ok");
  std::this_thread::sleep_for(std::chrono::milliseconds(700));  // under way: about 1 s of its 2 s
  fw.power_cut();
  CHECK(fw.pid() == -1);
  CHECK(fw.port().empty());
  FirmwareRecord cut = fw.record();
  REQUIRE(cut.sessions.size() == 1);
  REQUIRE(cut.sessions[0].blocks.size() == 2);
  const ExecutedBlock& b = cut.sessions[0].blocks[0];
  REQUIRE(b.run == ExecutedBlock::Run::Partial);
  CHECK(b.stop.x > 0);
  CHECK(b.stop.x < 10000);
  CHECK(cut.sessions[0].blocks[1].run == ExecutedBlock::Run::NotRun);
  JobCheck jc = check_job(job, cut, PenRule::servo());
  CHECK(jc.marks.partial == 1);
  CHECK(jc.marks.lost == 2);
  // Power on: a new process, settings kept in its EEPROM, the machine at zero.
  std::string port = fw.power_on();
  CHECK(!port.empty());
  CHECK(fw.status().find("MPos:0.000,0.000,0.000") != std::string::npos);
  auto dump = fw.command("$$");
  CHECK(std::find(dump.begin(), dump.end(), "$110=9000.000") != dump.end());
  FirmwareRecord again = fw.record();
  CHECK(again.sessions.size() == 2);
  CHECK(again.sessions[1].blocks.empty());
}

// grbl_avr's clock runs at -t times the wall clock, or as fast as it can (about 2.4x real
// time here) with -t 0. The firmware's record is in simulated time, so the timescale must
// change nothing but the host's latency as grbl sees it. The job opens with a 1 s dwell:
// its bytes fit grbl's RX buffer, so every line is waiting in grbl before the first move,
// however late a loaded host's relay thread runs.
TEST_CASE("grbl firmware: the step log and plot times do not depend on the -t timescale", "[firmware]") {
  const std::string job =
      "G21\nG90\nG4 P1\nG0 X5 Y5\nM3 S1000\nG4 P0.1\nG1 X25 Y5 F3000\nG1 X25 Y15\nG1 X5 Y5\nM5\nG4 P0.1\nG0 X0 Y0\n";
  REQUIRE(job.size() < 127);
  std::vector<SessionRecord> runs;
  for (double t : {1.0, 0.0}) {
    FirmwareOptions o = GrblFirmware::with_settings("grbl-servo");
    o.timescale = t;
    GrblFirmware fw(o);
    for (const std::string& reply : fw.stream(gcode_lines(job))) REQUIRE(reply == "ok");
    REQUIRE(fw.wait_idle(30));
    runs.push_back(fw.record().sessions.at(0));
  }
  REQUIRE(runs[0].blocks.size() == 5);
  REQUIRE(runs[1].blocks.size() == runs[0].blocks.size());
  // The same steps in the same order, at the same times from the first step on.
  REQUIRE(runs[0].step_log.steps.size() == runs[1].step_log.steps.size());
  const double t0 = runs[0].step_log.steps[0].t, t1 = runs[1].step_log.steps[0].t;
  for (size_t i = 0; i < runs[0].step_log.steps.size(); ++i) {
    const StepEvent &a = runs[0].step_log.steps[i], &b = runs[1].step_log.steps[i];
    REQUIRE(a.pos == b.pos);
    REQUIRE(b.t - t1 == Approx(a.t - t0).margin(0.002));
  }
  for (size_t k = 0; k < runs[0].blocks.size(); ++k) {
    const ExecutedBlock &a = runs[0].blocks[k], &b = runs[1].blocks[k];
    CHECK(a.planned.end == b.planned.end);
    CHECK(a.run == ExecutedBlock::Run::Complete);
    CHECK(b.run == ExecutedBlock::Run::Complete);
    CHECK(a.duty == b.duty);
  }
}
