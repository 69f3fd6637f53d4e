// The fault matrix: every fault the simulators inject x grbl and HPGL x a dot job and a
// stroke job. Each cell plots with the fault, resumes from the journal until the job is
// done (at most four sessions, on the same simulated machine), and compares what the
// machine drew with the job: lost = planned marks never drawn, doubled = marks drawn
// twice, stray = marks the job does not have (a piece of a move cut short by a reset
// or a hold is counted as neither when it lies along a planned move).
#include <catch2/catch.hpp>
#include <cstdio>

#include "compare.hpp"
#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "drivers/job/segments.hpp"
#include "drivers/stream/grbl/streamer.hpp"
#include "drivers/stream/hpgl/streamer.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/resume.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "fast_sim.hpp"
#include "jobgen.hpp"
#include "sim/grbl_sim.hpp"
#include "sim/hpgl_sim.hpp"
#include "test_util.hpp"

using namespace stipplot;
using namespace stipplot::io;

namespace {

struct Cell {
  size_t lost = 0, doubled = 0, stray = 0, sessions = 0;
  bool completed = false;
};

enum class Fault { drop_reply, corrupt_reply, stall, disconnect, error_line, alarm_line, reset };
const char* name(Fault f) {
  static const char* n[] = {"drop-reply", "corrupt-reply", "stall", "disconnect", "error-line", "alarm-line", "reset"};
  return n[static_cast<int>(f)];
}

sim::Faults faults_for(Fault f, bool hpgl) {
  sim::Faults s;
  switch (f) {
    case Fault::drop_reply: s.drop_reply = 12; break;
    case Fault::corrupt_reply: s.corrupt_reply = 12; break;
    case Fault::stall: s.stall_line = 14, s.stall_ms = 3000; break;
    case Fault::disconnect: s.disconnect_after_bytes = hpgl ? 500 : 700; break;
    case Fault::error_line: s.error_line = 25; break;
    case Fault::alarm_line:
      s.alarm_line = 25;
      s.not_ready_ms = 120000;  // HPGL: the operator lowers the paper lever after two device minutes
      break;
    case Fault::reset: s.reset_line = 25; break;
  }
  return s;
}

// Dots (one-point strokes) or strokes, 20 of them.
testjob::Strokes marks(bool dots) { return testjob::random_strokes(dots ? 61 : 62, 20, dots ? 1 : 5); }

Cell score(const Job& job, const std::vector<Segment>& drawn) {
  const auto planned = job_segments(job);
  const auto d = testjob::compare(planned, drawn);
  Cell c;
  c.lost = d.missing;
  c.doubled = d.duplicated;
  for (const auto& s : drawn)
    if (!testjob::along_planned(s, planned)) ++c.stray;
  return c;
}

template <class Streamer, class Options>
bool run_session(Streamer& st, const Job& job, const std::string& jpath, size_t session, const ResumePlan& rp) {
  JournalHeader h;
  h.total_lines = job.lines.size();
  Journal journal(jpath, h, session > 0);
  try {
    return st.stream(job, rp.next, rp.preamble, &journal).completed;
  } catch (const UserError&) {  // the fault stopped it: resume
    return false;
  }
}

// Plots the job on the simulated machine, resuming from the journal until it is done (at
// most four sessions), and scores what the machine drew.
template <class Streamer, class Options>
Cell plot_until_done(const Job& job, sim::SimDevice& sim, const std::string& jpath, const Options& o) {
  Cell c;
  for (size_t session = 0; session < 4 && !c.completed; ++session) {
    PosixSerial port(sim.open_pty(), {});
    Streamer st(port, o);
    try {
      st.connect();
    } catch (const UserError&) {
      continue;
    }
    ResumePlan rp{0, {}, {}, 0, {}};
    if (session > 0) rp = resume_from_journal(job, Journal::load(jpath), st.device_pen(), st.resume_window());
    c.completed = run_session<Streamer, Options>(st, job, jpath, session, rp);
    c.sessions = session + 1;
  }
  sim.wait_idle(20);
  const Cell s = score(job, sim.record());
  c.lost = s.lost, c.doubled = s.doubled, c.stray = s.stray;
  return c;
}

Cell grbl_cell(Fault fault, bool dots) {
  const Job job = parse_gcode_job(testjob::gcode(marks(dots)));
  sim::GrblSim sim(testjob::fast_sim<sim::GrblSimConfig>(faults_for(fault, false)));
  test::TempDir t;
  grbl::Options o;
  o.unlock = true;  // after an alarm: the operator has looked
  o.lost_reply_after = Millis(300);
  o.watchdog = Millis(3000);
  return plot_until_done<grbl::Streamer>(job, sim, t.file("m.gcode.journal"), o);
}

Cell hpgl_cell(Fault fault, bool dots) {
  const Job job = parse_hpgl_job(testjob::hpgl(marks(dots)));
  sim::HpglSim sim(testjob::fast_sim<sim::HpglSimConfig>(faults_for(fault, true)));
  test::TempDir t;
  hpgl::Options o;
  o.watchdog = Millis(3000);
  o.not_ready_timeout = Millis(2000);
  // The default 20 ms between buffer polls, in the device's time: the simulator runs 40
  // times faster (an error is placed within the instructions done between two polls).
  o.poll_interval = Millis(1);
  return plot_until_done<hpgl::Streamer>(job, sim, t.file("m.hpgl.journal"), o);
}

void report_cell(const char* protocol, Fault f, bool dots, const Cell& c) {
  std::printf("fault matrix | %-13s | %-4s | %-6s | lost %zu | doubled %zu | stray %zu | sessions %zu%s\n", name(f),
              protocol, dots ? "dots" : "stroke", c.lost, c.doubled, c.stray, c.sessions,
              c.completed ? "" : " | NOT COMPLETED");
  std::fflush(stdout);
}

void check_cell(const char* protocol, Fault f, bool dots, const Cell& c) {
  INFO(protocol << " " << name(f) << " " << (dots ? "dots" : "stroke"));
  CHECK(c.completed);
  CHECK(c.lost == 0);
  CHECK(c.doubled <= 1);
  CHECK(c.stray == 0);
}

constexpr Fault kFaults[] = {Fault::drop_reply, Fault::corrupt_reply, Fault::stall, Fault::disconnect,
                             Fault::error_line, Fault::alarm_line, Fault::reset};

// Every cell of one protocol, each asserted.
template <class RunCell>
void matrix(const char* protocol, RunCell run_cell) {
  for (const Fault f : kFaults)
    for (const bool dots : {true, false}) {
      const Cell c = run_cell(f, dots);
      report_cell(protocol, f, dots, c);
      check_cell(protocol, f, dots, c);
    }
}

}  // namespace

TEST_CASE("fault matrix: grbl, every simulator fault, dots and strokes: nothing lost, at most one move doubled",
          "[drivers][grbl][faults][matrix]") {
  matrix("grbl", grbl_cell);
}

TEST_CASE("fault matrix: HPGL, every simulator fault, dots and strokes: nothing lost, at most one move doubled",
          "[drivers][hpgl][faults][matrix]") {
  matrix("hpgl", hpgl_cell);
}
