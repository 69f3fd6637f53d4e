// Power loss mid-plot: the board stops where it is, loses its buffers and its position,
// and comes back fresh. The resume (resume_from_journal, as `plot --resume`) must lose no
// mark and draw again only what the journal's last status report could not prove drawn;
// and the "pos" journal record that carries that proof.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "drivers/job/segments.hpp"
#include "drivers/stream/grbl/streamer.hpp"
#include "drivers/stream/hpgl/streamer.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/resume.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "jobgen.hpp"
#include "sim/grbl_sim.hpp"
#include "sim/hpgl_sim.hpp"

using namespace stipplot;
using namespace stipplot::io;

namespace {

std::string pl_temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("stipplot-pl-" + std::to_string(::getpid()) + "-" + name)).string();
}

// Long wavy strokes of 5 mm moves with no sync line inside them: grbl's planner holds 15
// of them (75 mm of pen-down path) acknowledged but not yet drawn.
testjob::Strokes pl_long_strokes() {
  testjob::Strokes s;
  for (int i = 0; i < 4; ++i) {
    std::vector<testjob::Pt> st;
    for (int j = 0; j <= 50; ++j) st.push_back({10 + 4.0 * j, 20 + 40.0 * i + 6 * std::sin(j * 0.7 + i)});
    s.push_back(st);
  }
  return s;
}

// What the machine drew against the job: planned pen-down length never covered (lost),
// pen-down length drawn more than once (redrawn), pieces along no planned move (stray),
// dots never drawn and dots drawn twice. O(planned x drawn).
struct PowerScore {
  double planned_mm = 0, lost_mm = 0, redrawn_mm = 0;
  size_t stray = 0, dots_lost = 0, dots_twice = 0;
};

// The part [t0, t1] of planned segment p that drawn segment s covers, if s lies along p.
bool along_segment(const Segment& p, const Segment& s, double& t0, double& t1) {
  const double dx = p.x1 - p.x0, dy = p.y1 - p.y0, len2 = dx * dx + dy * dy;
  auto param = [&](double x, double y, double& t) {
    t = ((x - p.x0) * dx + (y - p.y0) * dy) / len2;
    return t > -1e-6 && t < 1 + 1e-6 && std::hypot(p.x0 + t * dx - x, p.y0 + t * dy - y) < 2e-3;
  };
  if (!(param(s.x0, s.y0, t0) && param(s.x1, s.y1, t1))) return false;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

PowerScore score_drawing(const Job& job, const std::vector<Segment>& drawn) {
  PowerScore sc;
  std::vector<bool> used(drawn.size(), false);
  for (const Segment& p : job_segments(job)) {
    const double len = std::hypot(p.x1 - p.x0, p.y1 - p.y0);
    if (len < 1e-9) {  // a dot: a touch at its point
      size_t n = 0;
      for (size_t i = 0; i < drawn.size(); ++i)
        if (std::hypot(drawn[i].x0 - p.x0, drawn[i].y0 - p.y0) < 2e-3 && std::hypot(drawn[i].x1 - p.x0, drawn[i].y1 - p.y0) < 2e-3)
          ++n, used[i] = true;
      sc.dots_lost += n == 0;
      sc.dots_twice += n > 1;
      continue;
    }
    sc.planned_mm += len;
    std::vector<std::pair<double, double>> cover;
    double drawn_len = 0;
    for (size_t i = 0; i < drawn.size(); ++i) {
      double t0, t1;
      if (drawn[i].pen != p.pen || !along_segment(p, drawn[i], t0, t1)) continue;
      used[i] = true;  // a touch on the stroke (the pen lowered where it stopped) is no stray mark
      if (t1 - t0 < 1e-9) continue;
      cover.push_back({t0, t1});
      drawn_len += (t1 - t0) * len;
    }
    std::sort(cover.begin(), cover.end());
    double reach = 0, covered = 0;
    for (auto [a, b] : cover) {
      if (b > reach) covered += b - std::max(a, reach), reach = b;
    }
    sc.lost_mm += std::max(0.0, (1 - covered) * len);
    sc.redrawn_mm += std::max(0.0, drawn_len - covered * len);
  }
  for (size_t i = 0; i < drawn.size(); ++i) sc.stray += !used[i];
  return sc;
}

struct PowerLoss {
  PowerScore score;
  ResumePlan plan;
  JournalState journal;
};

// Plots `job` on a simulated grbl that loses power `loss_s` device seconds after the
// first byte came (the first session's connect, then the job), then powers on a
// fresh board on the same machine and resumes from the journal until done. The clock runs
// 10 times fast and the status is asked 50 times a second: a report every 0.2 s of device
// time, as the real streamer's 5 Hz.
PowerLoss plot_through_power_loss(const Job& job, double loss_s, const std::string& name) {
  sim::GrblSimConfig cfg;
  cfg.speedup = 10;
  cfg.faults.power_loss_after_s = loss_s;
  sim::GrblSim sim(cfg);
  grbl::Options o;
  o.poll_hz = 50;
  const std::string jpath = pl_temp_path(name + ".journal");
  {
    PosixSerial port(sim.open_pty(), {});
    grbl::Streamer st(port, o);
    st.connect();
    JournalHeader h;
    h.total_lines = job.lines.size();
    Journal journal(jpath, h);
    CHECK_THROWS_AS(st.stream(job, 0, {}, &journal), TransportError);  // the port went with the power
  }
  PowerLoss out;
  out.journal = Journal::load(jpath);
  PosixSerial port(sim.open_pty(), {});
  grbl::Streamer st(port, o);
  st.connect();
  REQUIRE(st.restarted());  // a fresh board: banner, position zeroed
  out.plan = resume_from_journal(job, out.journal, st.device_pen(), st.resume_window());
  {
    Journal journal(jpath, {}, true);
    CHECK(st.stream(job, out.plan.next, out.plan.preamble, &journal).completed);
  }
  REQUIRE(sim.wait_idle(30));
  REQUIRE(sim.boots() == 1);
  out.score = score_drawing(job, sim.record());
  std::filesystem::remove(jpath);
  return out;
}

}  // namespace

namespace {

// Many short strokes (a tree's, a sketch's): pen lifts between them, so grbl's planner
// holds the current stroke only, and a window of 15 moves reaches back over strokes a
// pen command's answer proved drawn.
testjob::Strokes pl_short_strokes() {
  testjob::Strokes s;
  for (int i = 0; i < 40; ++i) {
    std::vector<testjob::Pt> st;
    for (int j = 0; j <= 6; ++j) st.push_back({10 + 8.0 * (i % 10) + 1.0 * j, 10 + 14.0 * (i / 10) + 4 * std::sin(j + i)});
    s.push_back(st);
  }
  return s;
}

}  // namespace

namespace {

// Strokes of three 25 mm moves: grbl's planner runs out within each stroke, and a status
// report lands mid-move, where the resume splits the line.
testjob::Strokes pl_long_moves() {
  testjob::Strokes s;
  for (int i = 0; i < 12; ++i)
    s.push_back({{10.0 + 6 * i, 10}, {35.0 + 6 * i, 10 + 2.0 * i}, {35.0 + 6 * i, 35 + 2.0 * i}, {10.0 + 6 * i, 40}});
  return s;
}

}  // namespace

TEST_CASE("power loss mid-stroke: resume from the last proof, nothing lost, little redrawn",
          "[drivers][grbl][resume][power]") {
  const char* names[] = {"40 short strokes", "4 long strokes", "12 strokes of 25 mm moves"};
  for (const int kind : {0, 1, 2}) {
    const Job job =
        parse_gcode_job(testjob::gcode(kind == 0 ? pl_short_strokes() : kind == 1 ? pl_long_strokes() : pl_long_moves()));
    for (const double at : {0.3, 0.55, 0.8}) {
      const PowerLoss pl = plot_through_power_loss(job, at * job.est_total_s, "strokes");
      const PowerScore& s = pl.score;
      JournalState unproved = pl.journal;  // as journals were before proofs
      unproved.proven = {};
      const ResumePlan before = resume_from_journal(job, unproved, {true, false, 0, 0}, {128, 15, 1, 0});
      std::printf("power loss at %.0f%% of a %.0f mm job of %s: resumed at line %zu, lost %.3f mm, redrawn %.2f mm "
                  "(plan: at most %.2f mm, %s; without proofs: line %zu, at most %.2f mm), stray %zu\n",
                  100 * at, s.planned_mm, names[kind], pl.plan.next + 1, s.lost_mm,
                  s.redrawn_mm, pl.plan.redraw, pl.plan.why.c_str(), before.next + 1, before.redraw, s.stray);
      INFO("at " << at << ": " << pl.plan.note);
      CHECK(pl.journal.proven.line >= 0);
      CHECK(s.lost_mm < 0.01);
      CHECK(s.stray == 0);
      CHECK(s.redrawn_mm <= 15);
      CHECK(s.redrawn_mm <= pl.plan.redraw + 0.05);  // the plan's figure is a bound
    }
  }
}

TEST_CASE("power loss in a dot job: no dot lost, at most one drawn twice", "[drivers][grbl][resume][power]") {
  testjob::Strokes dots;
  for (int i = 0; i < 60; ++i) dots.push_back({{10 + 3.0 * (i % 20), 10 + 3.0 * (i / 20)}});
  const Job job = parse_gcode_job(testjob::gcode(dots));
  for (const double at : {0.3, 0.6, 0.9}) {
    const PowerLoss pl = plot_through_power_loss(job, at * job.est_total_s, "dots");
    const PowerScore& s = pl.score;
    std::printf("power loss at %.0f%% of a 60-dot job: resumed at line %zu, dots lost %zu, drawn twice %zu, stray %zu "
                "(%s)\n",
                100 * at, pl.plan.next + 1, s.dots_lost, s.dots_twice, s.stray, pl.plan.why.c_str());
    CHECK(s.dots_lost == 0);
    CHECK(s.dots_twice <= 1);
    CHECK(s.stray == 0);
    CHECK(s.redrawn_mm == 0);
  }
}

namespace {

// An HPGL plotter paced by XON/XOFF: a line counts as acknowledged once written, so up to
// a buffer (1 KB) of it may be undrawn when the power goes. ESC.B polls while writing
// prove what the plotter has taken; the resume starts at the first line not wholly taken.
PowerLoss plot_hpgl_through_power_loss(const Job& job, double loss_s) {
  sim::HpglSimConfig c;
  c.xonxoff = true;
  c.speedup = 8;
  c.xoff_free = 384;  // room for what is in flight when XOFF leaves (the host's reaction is scaled 8x)
  c.xon_free = 640;
  // The host writes at a quarter of the simulated link's rate (23 KB/s, still ten times what
  // the plot takes): the simulator reads its pty only when its thread runs, and at the full
  // rate a 4 ms stall of that thread left more than the 384 bytes of room unread when its
  // XOFF went out (a CI run lost 21 mm to it); at this rate the room lasts 17 ms.
  c.link.baud = 115200;
  c.faults.power_loss_after_s = loss_s;
  sim::HpglSim sim(c);
  hpgl::Options o;
  o.handshake = HpglHandshake::xonxoff;
  o.newline = true;
  o.proof_interval = Millis(25);  // 0.2 s of device time
  const std::string jpath = pl_temp_path("hpgl.journal");
  {
    PosixSerial port(sim.open_pty(), {});
    port.pace(115200 / 10.0 * 2);
    hpgl::Streamer st(port, o);
    st.connect();
    JournalHeader h;
    h.total_lines = job.lines.size();
    Journal journal(jpath, h);
    CHECK_THROWS_AS(st.stream(job, 0, {}, &journal), TransportError);
  }
  PowerLoss out;
  out.journal = Journal::load(jpath);
  PosixSerial port(sim.open_pty(), {});
  port.pace(115200 / 10.0 * 2);
  hpgl::Streamer st(port, o);
  st.connect();
  out.plan = resume_from_journal(job, out.journal, st.device_pen(), st.resume_window());
  {
    Journal journal(jpath, {}, true);
    CHECK(st.stream(job, out.plan.next, out.plan.preamble, &journal).completed);
  }
  REQUIRE(sim.wait_idle(30));
  out.score = score_drawing(job, sim.record());
  std::filesystem::remove(jpath);
  return out;
}

}  // namespace

TEST_CASE("power loss on an HPGL plotter paced by XON/XOFF: nothing lost, resumed from what left its buffer",
          "[drivers][hpgl][resume][power]") {
  const Job job = parse_hpgl_job(testjob::hpgl(pl_short_strokes()));
  constexpr double upm = 40;  // plotter units a mm (jobgen's)
  for (const double at : {0.3, 0.55, 0.8}) {
    const PowerLoss pl = plot_hpgl_through_power_loss(job, at * job.est_total_s);
    const PowerScore& s = pl.score;
    std::printf("HPGL power loss at %.0f%% of a %.0f mm job: resumed at line %zu, lost %.3f mm, redrawn %.2f mm "
                "(plan: at most %.2f mm, %s), stray %zu\n",
                100 * at, s.planned_mm / upm, pl.plan.next + 1, s.lost_mm / upm, s.redrawn_mm / upm, pl.plan.redraw / upm,
                pl.plan.why.c_str(), s.stray);
    INFO("at " << at << ": " << pl.plan.note);
    CHECK(pl.journal.proven.line >= 0);
    CHECK(s.lost_mm / upm < 0.01);
    CHECK(s.stray == 0);
    // An instruction is the unit: what the plotter finished since the last poll (0.2 s of
    // device time) is drawn again, whole strokes here (at most 20 mm each).
    CHECK(s.redrawn_mm / upm <= 40);
  }
}

// lines: 0 G21, 1 G90, 2 M5, 3 G0 X10 Y10, 4 M3 S30, 5 G1 X20 Y10 F600, 6 G1 X20 Y20,
//        7 G1 X10 Y20, 8 M5, 9 G0 X0 Y0
TEST_CASE("resume after a fresh board: the proof splits the line, an inconsistent proof falls back",
          "[drivers][resume][power]") {
  const Job job = parse_gcode_job("G21\nG90\nM5\nG0 X10 Y10\nM3 S30\nG1 X20 Y10 F600\nG1 X20 Y20\nG1 X10 Y20\nM5\nG0 X0 Y0\n");
  REQUIRE(job.lines.size() == 10);
  const DevicePen fresh{true, false, 0, 0};   // re-zeroed at the origin, pen up
  const ResumeWindow grbl_window{128, 3, 1, 0};  // its planner lost (3 blocks, so the window starts at line 6)
  JournalState js;
  js.last_acked = 7;
  js.proven = {6, 20.001, 13.5, 0};  // a status report on line 7 (G1 X20 Y20), 3.5 mm along
  ResumePlan rp = resume_from_journal(job, js, fresh, grbl_window);
  CHECK(rp.next == 6);
  REQUIRE(rp.preamble.size() >= 3);
  CHECK(std::find(rp.preamble.begin(), rp.preamble.end(), "G0 X20.0000 Y13.5000") != rp.preamble.end());  // projected
  CHECK(std::find(rp.preamble.begin(), rp.preamble.end(), "M3 S30") != rp.preamble.end());
  CHECK(rp.redraw == Approx(6.5 + 10));  // the rest of line 7 and line 8, acknowledged
  CHECK(rp.why.find("last point proved drawn") != std::string::npos);
  // At the end of a line: that line is done.
  js.proven = {6, 20, 20, 0};
  CHECK(resume_from_journal(job, js, fresh, grbl_window).next == 7);
  // Off the line's path, or past the acknowledged lines: today's window start (line 4).
  for (const ProvenPoint bad : {ProvenPoint{6, 25, 13.5, 0}, ProvenPoint{9, 5, 10, 0}}) {
    js.proven = bad;
    rp = resume_from_journal(job, js, fresh, grbl_window);
    CHECK(rp.next == 4);  // settled back to the stroke's pen-down
    CHECK(rp.why.find("may not have run") != std::string::npos);
    CHECK(rp.redraw == Approx(30));
  }
  // No proof: the same, as journals before "pos" records.
  js.proven = {};
  CHECK(resume_from_journal(job, js, fresh, grbl_window).next == 4);
  // A device that kept its position still decides (the proof only speaks for a fresh one).
  js.proven = {6, 20, 13.5, 0};
  CHECK(resume_from_journal(job, js, DevicePen{true, false, 10, 20}, grbl_window).next == 9);
  // A sync line's answer proves the start of the next line (the first not acknowledged).
  js.last_acked = 8;
  js.proven = {9, 10, 20, 0};
  CHECK(resume_from_journal(job, js, fresh, grbl_window).next == 9);
  js.proven = {10, 0, 0, 0};
  CHECK(resume_from_journal(job, js, fresh, grbl_window).next < 9);  // beyond the job: ignored
  // HPGL: an instruction may be a polyline, so a proof inside it (even on its chord) is no
  // proof; at its start it is. Lines: 0 IN, 1 SP1, 2 PU400,400, 3 PD800,400,800,800, 4 PU, 5 SP0
  const Job hp = parse_hpgl_job("IN;SP1;PU400,400;PD800,400,800,800;PU;SP0;");
  REQUIRE(hp.lines.size() == 6);
  JournalState hj;
  hj.last_acked = 4;
  const ResumeWindow paced{1024, 0, 0, 1024};
  hj.proven = {3, 600, 600, 0};  // on the chord (400,400)-(800,800), not on the path
  CHECK(resume_from_journal(hp, hj, DevicePen{}, paced).next == 0);
  hj.proven = {3, 400, 400, 0};
  CHECK(resume_from_journal(hp, hj, DevicePen{}, paced).next == 3);
}

// The real grbl on simavr, as a board whose port opens after its reset: the fresh board
// sends no banner on connect, so the streamer never saw it restart (back_moves 0). Its
// planner was lost all the same: the acknowledged moves it may have held are undrawn.
TEST_CASE("resume after a fresh board nobody saw restart: the moves its planner held count as undrawn",
          "[drivers][resume][power]") {
  const Job job = parse_gcode_job("G21\nG90\nM5\nG0 X10 Y10\nM3 S30\nG1 X20 Y10 F600\nG1 X20 Y20\nG1 X10 Y20\nM5\nG0 X0 Y0\n");
  const DevicePen fresh{true, false, 0, 0};
  const ResumeWindow unseen{128, 0, 1, 0, 3};  // no restart seen; 3 moves may be held unrun
  JournalState js;
  js.last_acked = 7;
  ResumePlan rp = resume_from_journal(job, js, fresh, unseen);
  CHECK(rp.next == 4);  // back 3 moves (lines 6-8), settled to the stroke's pen-down
  CHECK(rp.redraw == Approx(30));
  js.proven = {6, 20.001, 13.5, 0};
  rp = resume_from_journal(job, js, fresh, unseen);
  CHECK(rp.next == 6);
  CHECK(rp.redraw == Approx(6.5 + 10));
  // Without the planner's moves (the window as it was), the board at the origin read as
  // the job's closing travel home: the three moves and the rest were skipped.
  js.proven = {};
  CHECK(resume_from_journal(job, js, fresh, ResumeWindow{128, 0, 1, 0, 0}).next == job.lines.size());
}

TEST_CASE("journal: pos records round-trip, the last wins, a torn one is ignored, a bad one refused",
          "[drivers][journal][power]") {
  const std::string path = pl_temp_path("pos.journal");
  JournalHeader h;
  h.dialect = "gcode";
  h.total_lines = 10;
  {
    Journal j(path, h, false, 0);
    j.ack(5);
    j.proven({4, 12.5, -3.25, 1});
    j.ack(6);
    j.proven({5, 20, 10.125, 0});
  }
  JournalState st = Journal::load(path);
  CHECK(st.last_acked == 6);
  CHECK(st.proven == ProvenPoint{5, 20, 10.125, 0});
  auto append = [&](const std::string& raw) { std::ofstream(path, std::ios::app) << raw; };
  append(Journal::record("pos 6 21.0000 11.0000 0.0000").substr(0, 12));  // cut mid-write
  st = Journal::load(path);
  CHECK(st.torn);
  CHECK(st.proven.line == 5);
  {
    Journal j(path, {}, true);  // the torn tail is cut off; a new session's proof wins
    j.proven({6, 21, 11, 0});
  }
  CHECK(Journal::load(path).proven == ProvenPoint{6, 21, 11, 0});
  append(Journal::record("pos 10 1 2 3") + "\n");
  CHECK_THROWS_WITH(Journal::load(path), Catch::Contains("`pos 10 1 2 3` is not a position on a line of the job"));
  {
    Journal j(path, h, false, 0);
    j.ack(2);
  }
  append(Journal::record("pos 1 nan 2 3") + "\n");
  CHECK_THROWS_WITH(Journal::load(path), Catch::Contains("line 3"));
  {
    Journal j(path, h, false, 0);  // a journal without proofs (as before them) reads as none
    j.ack(2);
  }
  CHECK(Journal::load(path).proven.line == -1);
  std::filesystem::remove(path);
}
