// The firmware harness itself: its log parsers on canned grbl-sim output, then the real
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

// A two-move job as grbl-sim 9bdd165 with build.sh's patches logs it (-r 0.001): a rapid
// to 10,10, the pen down, 10 mm at F3000, the pen up; samples thinned out.
const char* kBlocks =
    "# reset at 1.05254 pos 0, 0, 0\n"
    "1000, 1000, 0, 0.000000, 1, 0, 14.1421\n"
    "2000, 1000, 0, 0.000000, 16, 1000, 10.0000\n"
    "# rx drop 1 at 2.00000 byte 0x47\n";
const char* kSteps =
    "# block number 0\n"
    "     1.33389 0, 0, 0, 0\n"
    "     1.33400 0, 0, 0, 0\n"
    "     1.33500 1, 1, 0, 0\n"
    "     1.33600 1, 1, 0, 0\n"
    "     1.33700 2, 2, 0, 0\n"
    "     1.33800 4, 4, 0, 0\n"
    "     1.33900 877, 877, 0, 0\n"  // planner empty: no lines until the pen is down
    "     1.71992 1000, 1000, 0, 255\n"
    "# block number 1\n"
    "     1.72000 1000, 1000, 0, 255\n"
    "     1.72100 1001, 1000, 0, 255\n"
    "     1.72200 1003, 1000, 0, 255\n"
    "     1.72291 1877, 1000, 0, 255\n"
    "     4.17899 2000, 1000, 0, 0\n";  // the line printed at exit

}  // namespace

TEST_CASE("firmware logs: block log epochs, resets and rx drops", "[firmware-logs]") {
  BlockLog bl = parse_block_log(kBlocks);
  REQUIRE(bl.resets.size() == 1);
  CHECK(bl.resets[0].t == Approx(1.05254));
  REQUIRE(bl.epochs.size() == 1);
  REQUIRE(bl.epochs[0].size() == 2);
  CHECK(bl.epochs[0][0].end == Steps{1000, 1000, 0});
  CHECK(bl.epochs[0][0].rapid());
  CHECK_FALSE(bl.epochs[0][0].spindle_on());
  CHECK(bl.epochs[0][1].spindle_on());
  CHECK(bl.epochs[0][1].spindle == 1000);
  CHECK(bl.rx_drops == 1);
}

TEST_CASE("firmware logs: the zeroed slots a reset leaves in the ring buffer are no blocks", "[firmware-logs]") {
  // Seen on a soft reset after a dead host's job: the logger ran between plan_reset() and
  // the banner and printed slots 2..15 as grbl had just zeroed them.
  std::string log = std::string(kBlocks);
  for (int i = 0; i < 14; ++i) log += "2000, 1000, 0, 0.000000, 0, 0, 0.0000\n";
  log += "# reset at 3.00000 pos 2000, 1000, 0\n3000, 1000, 0, 0.000000, 1, 0, 10.0000\n";
  BlockLog bl = parse_block_log(log);
  REQUIRE(bl.epochs.size() == 2);
  CHECK(bl.epochs[0].size() == 2);
  CHECK(bl.epochs[1].size() == 1);
  CHECK(bl.zeroed_slots == 14);
}

TEST_CASE("firmware logs: step log pauses are the planner running dry", "[firmware-logs]") {
  StepLog sl = parse_step_log(kSteps, 0.001, false, true);
  REQUIRE(sl.lines.size() == 12);  // the exit line dropped
  REQUIRE(sl.empties.size() == 2);
  CHECK(sl.empties[0].t_emptied == Approx(1.33900));
  CHECK(sl.empties[0].pos_emptied == Steps{877, 877, 0});
  CHECK(sl.empties[0].t_resumed == Approx(1.71992));
  CHECK(sl.empties[0].pos_resumed == Steps{1000, 1000, 0});
  CHECK(sl.empties[1].t_emptied == Approx(1.72291));
  CHECK(sl.empties[1].t_resumed < 0);
  // Frozen mid-move (a power cut right after the last sample): no final pause.
  StepLog cut = parse_step_log(std::string(kSteps).substr(0, std::string(kSteps).rfind("     1.72291")), 0.001, true);
  CHECK(cut.empties.size() == 1);
  CHECK(cut.ends_moving);
}

TEST_CASE("firmware logs: a session joins both logs and the rest time follows the deceleration", "[firmware-logs]") {
  MachineSettings s = MachineSettings::parse("$100=100\n$101=100\n$102=100\n$120=1000\n$121=1000\n$122=1000\n");
  SessionRecord r = build_session(parse_block_log(kBlocks), parse_step_log(kSteps, 0.001, false, true), s, false, 0);
  REQUIRE(r.blocks.size() == 2);
  CHECK(r.blocks[0].run == ExecutedBlock::Run::Complete);
  CHECK(r.blocks[0].start == Steps{0, 0, 0});
  CHECK(r.blocks[0].t_start == Approx(1.33389));
  CHECK(r.blocks[1].start == Steps{1000, 1000, 0});
  CHECK(r.blocks[1].t_start == Approx(1.71992));
  REQUIRE(r.rests.size() == 1);
  CHECK(r.rests[0].block == 0);
  CHECK(r.rests[0].full_stop);
  // 1.23 mm diagonally left at 1414 mm/s^2: sqrt(2 * 1.739 / 1414.2) = 49.6 ms.
  CHECK(r.blocks[0].t_end == Approx(1.339 + std::sqrt(2 * std::hypot(1.23, 1.23) / (1000 * std::sqrt(2.0)))).epsilon(1e-6));
  CHECK(r.blocks[1].rest_after);
  // The same log cut by a power cut in block 1, 3 steps past its start.
  std::string cut = std::string(kSteps).substr(0, std::string(kSteps).rfind("     1.72291"));
  SessionRecord c = build_session(parse_block_log(kBlocks), parse_step_log(cut, 0.001, true), s, true, 0.0);
  CHECK(c.blocks[0].run == ExecutedBlock::Run::Complete);
  CHECK(c.blocks[1].run == ExecutedBlock::Run::Partial);
  CHECK(c.blocks[1].stop == Steps{1003, 1000, 0});
  CHECK_FALSE(c.ambiguous_cut);
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
  for (const auto& i : jc.firmware.inconsistencies) INFO(i);
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

// grbl-sim's clock runs at -t times the wall clock, or as fast as it can (about 1-2x
// real time on the CI machine) when that is less. The firmware's record is in simulated
// time, so a larger -t must change nothing but the host's latency as grbl sees it.
// The job opens with a 1 s dwell: its 94 bytes fit grbl's RX buffer and the relay
// delivers them in 8 ms of wall time, so every line is waiting in grbl before the first
// move, whatever the timescale and however late a loaded host's relay thread runs (at
// -t 20 a 10 ms stall of the relay is 200 ms of grbl's time: without the dwell a late
// line made the planner stop between moves and the times differ by tens of ms).
TEST_CASE("grbl firmware: the block log and plot times do not depend on the -t timescale", "[firmware]") {
  const std::string job =
      "G21\nG90\nG4 P1\nG0 X5 Y5\nM3 S1000\nG4 P0.1\nG1 X25 Y5 F3000\nG1 X25 Y15\nG1 X5 Y5\nM5\nG4 P0.1\nG0 X0 Y0\n";
  REQUIRE(job.size() < 127);
  std::vector<SessionRecord> runs;
  for (double t : {1.0, 20.0}) {
    FirmwareOptions o = GrblFirmware::with_settings("grbl-servo");
    o.timescale = t;
    GrblFirmware fw(o);
    for (const std::string& reply : fw.stream(gcode_lines(job))) REQUIRE(reply == "ok");
    REQUIRE(fw.wait_idle(30));
    runs.push_back(fw.record().sessions.at(0));
  }
  REQUIRE(runs[0].blocks.size() == 5);
  REQUIRE(runs[1].blocks.size() == runs[0].blocks.size());
  for (size_t k = 0; k < runs[0].blocks.size(); ++k) {
    const ExecutedBlock &a = runs[0].blocks[k], &b = runs[1].blocks[k];
    CHECK(a.planned.end == b.planned.end);
    CHECK(a.planned.condition == b.planned.condition);
    CHECK(a.planned.spindle == b.planned.spindle);
    // Times from the first block's start agree to a few ms: dwells and moves are simulated
    // exactly; what differs is when grbl got each line.
    CHECK((a.t_start >= 0) == (b.t_start >= 0));
    CHECK((a.t_end >= 0) == (b.t_end >= 0));
    if (a.t_start >= 0 && b.t_start >= 0)
      CHECK(b.t_start - runs[1].blocks[0].t_start == Approx(a.t_start - runs[0].blocks[0].t_start).margin(0.01));
    if (a.t_end >= 0 && b.t_end >= 0)
      CHECK(b.t_end - runs[1].blocks[0].t_start == Approx(a.t_end - runs[0].blocks[0].t_start).margin(0.01));
  }
}
