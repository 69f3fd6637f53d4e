// End-to-end: the HPGL streamer against the simulated HPGL plotter over a pty, with
// each handshake and injected fault.
#include <catch2/catch.hpp>
#include <filesystem>

#include "compare.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "drivers/job/segments.hpp"
#include "drivers/stream/device_error.hpp"
#include "drivers/stream/hpgl/streamer.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/resume.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "fast_sim.hpp"
#include "jobgen.hpp"
#include "sim/hpgl_sim.hpp"
#include "test_util.hpp"

using namespace stipplot;
using namespace stipplot::io;

namespace {

sim::HpglSimConfig fast(sim::Faults f = {}) { return testjob::fast_sim<sim::HpglSimConfig>(f); }

// A simulated plotter on a pty and a streamer connected to it.
struct HpglRun {
  sim::HpglSim sim;
  PosixSerial port;
  hpgl::Streamer st;
  explicit HpglRun(const sim::HpglSimConfig& c, hpgl::Options o = {}, double pace_bytes_s = 0)
      : sim(c), port(sim.open_pty(), {}), st(port, std::move(o)) {
    if (pace_bytes_s > 0) port.pace(pace_bytes_s);
    st.connect();
  }
};

Job hpgl_job(uint64_t seed, int strokes = 25) { return parse_hpgl_job(testjob::hpgl(testjob::random_strokes(seed, strokes, 8))); }

}  // namespace

TEST_CASE("HPGL parsing splits instructions and finds the drawn segments", "[drivers][hpgl]") {
  Job j = parse_hpgl_job("IN;SP1;PU100,100;PD200,100,200,200;PU;PA300,300;PD;PU;PR10,0;PD10,0;SP0;");
  REQUIRE(j.lines.size() >= 9);
  CHECK(j.lines[0].text == "IN;");
  auto segs = job_segments(j);
  REQUIRE(segs.size() == 4);
  CHECK(segs[0] == Segment{100, 100, 200, 100, 1});
  CHECK(segs[1] == Segment{200, 100, 200, 200, 1});
  CHECK(segs[2] == Segment{300, 300, 300, 300, 1});  // a touch
  CHECK(segs[3] == Segment{310, 300, 320, 300, 1});
  CHECK_THROWS_AS(parse_hpgl_job("IN;1,2;"), UserError);
}

TEST_CASE("ESC.B polling never overfills the buffer and draws exactly the job", "[drivers][hpgl][e2e]") {
  HpglRun run(fast());
  Job job = hpgl_job(21);
  CHECK(run.st.buffer_bytes() == 1024);
  StreamResult r = run.st.stream(job, 0, {}, nullptr);
  CHECK(r.completed);
  REQUIRE(run.sim.wait_idle(20));
  auto d = testjob::compare(job_segments(job), run.sim.record());
  INFO(d.str());
  CHECK(d.equal());
  CHECK(run.sim.stats().rx_overflow == 0);
  CHECK(r.last_acked == static_cast<long>(job.lines.size()) - 1);
}

TEST_CASE("XON/XOFF at 115200 baud with paced writes: no overflow, exact drawing", "[drivers][hpgl][e2e]") {
  sim::HpglSimConfig c = fast();
  c.xonxoff = true;
  c.speedup = 8;
  c.xoff_free = 384;  // room for what is in flight when XOFF leaves (the host's reaction is scaled 8x)
  c.xon_free = 640;
  c.link.baud = 115200;  // in device time, which runs 8x: the host paces to match
  hpgl::Options o;
  o.handshake = HpglHandshake::xonxoff;
  o.newline = true;
  HpglRun run(c, o, 115200 / 10.0 * 8);
  Job job = hpgl_job(22, 12);
  StreamResult r = run.st.stream(job, 0, {}, nullptr);
  CHECK(r.completed);
  REQUIRE(run.sim.wait_idle(20));
  CHECK(run.sim.stats().rx_overflow == 0);
  CHECK(testjob::compare(job_segments(job), run.sim.record()).equal());
}

TEST_CASE("without any handshake a fast host overfills the plotter (the simulator notices)", "[drivers][hpgl]") {
  sim::HpglSimConfig c = fast();
  c.speedup = 5;
  Job job = hpgl_job(23, 120);
  hpgl::Options o;
  o.handshake = HpglHandshake::hardware;  // but a pty has no RTS/CTS
  o.status_queries = false;
  HpglRun run(c, o);
  run.st.stream(job, 0, {}, nullptr);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  CHECK(run.sim.stats().rx_overflow > 0);
  // With status queries the streamer notices and says the job is incomplete.
  o.status_queries = true;
  HpglRun run2(c, o);
  CHECK_THROWS_AS(run2.st.stream(job, 0, {}, nullptr), DeviceError);
  CHECK(run2.sim.stats().rx_overflow > 0);
}

TEST_CASE("HPGL faults: lost and garbled replies are asked again, errors and not-ready stop", "[drivers][hpgl][faults]") {
  Job job = hpgl_job(24, 15);
  for (int kind = 0; kind < 2; ++kind) {
    sim::Faults f;
    (kind == 0 ? f.drop_reply : f.corrupt_reply) = 5;
    hpgl::Options o;
    o.reply_timeout = Millis(300);
    HpglRun run(fast(f), o);
    CHECK(run.st.stream(job, 0, {}, nullptr).completed);
    REQUIRE(run.sim.wait_idle(20));
    CHECK(testjob::compare(job_segments(job), run.sim.record()).equal());
  }
  {
    sim::Faults f;
    f.error_line = 6;
    HpglRun run(fast(f));
    try {
      run.st.stream(job, 0, {}, nullptr);
      FAIL("no error");
    } catch (const DeviceError& e) {
      CHECK(e.code() == 1);
      CHECK(std::string(e.what()).find("instruction not recognized") != std::string::npos);
    }
  }
  {
    sim::Faults f;
    f.alarm_line = 8;
    hpgl::Options o;
    o.not_ready_timeout = Millis(500);
    HpglRun run(fast(f), o);
    CHECK_THROWS_WITH(run.st.stream(job, 0, {}, nullptr), Catch::Contains("not ready"));
  }
}

TEST_CASE("HPGL: a vanished port leaves a journal, resume loses nothing", "[drivers][hpgl][resume]") {
  auto dir = std::filesystem::temp_directory_path() / ("stipplot-hpgl-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::string jpath = (dir / "job.hpgl.journal").string();
  Job job = hpgl_job(25, 30);
  sim::Faults f;
  f.disconnect_after_bytes = 700;
  sim::HpglSim sim(fast(f));
  {
    PosixSerial port(sim.open_pty(), {});
    hpgl::Streamer st(port, {});
    st.connect();
    JournalHeader h;
    h.total_lines = job.lines.size();
    Journal journal(jpath, h);
    CHECK_THROWS_AS(st.stream(job, 0, {}, &journal), TransportError);
  }
  JournalState js = Journal::load(jpath);
  REQUIRE(static_cast<size_t>(js.last_acked + 1) < job.lines.size());
  PosixSerial port2(sim.open_pty(), {});
  hpgl::Streamer st2(port2, {});
  st2.connect();
  ResumePlan rp = plan_resume(job, static_cast<size_t>(js.last_acked + 1));
  Journal journal2(jpath, {}, true);
  CHECK(st2.stream(job, rp.next, rp.preamble, &journal2).completed);
  REQUIRE(sim.wait_idle(20));
  auto d = testjob::compare(job_segments(job), sim.record());
  INFO(d.str());
  // HPGL has no per-line acknowledgement: what the plotter did after its last ESC.B
  // answer may be drawn again, but nothing is lost and nothing foreign is drawn.
  CHECK(d.missing == 0);
  CHECK(d.extra == 0);
  std::filesystem::remove_all(dir);
}

namespace {

// Two halves of a stroke job with the writer's reload pause between them.
std::string hpgl_with_pause(std::string& first_half) {
  const auto strokes = testjob::random_strokes(44, 12, 6);
  const testjob::Strokes a(strokes.begin(), strokes.begin() + 6), b(strokes.begin() + 6, strokes.end());
  first_half = testjob::hpgl(a);
  return first_half + hpgl_pause_instruction("load pen 7 red #ff0000 in slot 1") + testjob::hpgl(b);
}

}  // namespace

TEST_CASE("HPGL pause: stops with everything before it drawn, names the pen, never sends the comment",
          "[drivers][hpgl][pause]") {
  std::string first;
  const Job job = parse_hpgl_job(hpgl_with_pause(first));
  const size_t before = job_segments(parse_hpgl_job(first)).size();
  long pause_line = -1;
  for (size_t i = 0; i < job.lines.size(); ++i)
    if (job.lines[i].pause) pause_line = static_cast<long>(i);
  REQUIRE(pause_line > 0);
  for (const bool polled : {true, false}) {
    hpgl::Options o;
    o.handshake = polled ? HpglHandshake::buffer_query : HpglHandshake::none;
    size_t asked = 0, drawn_then = 0;
    sim::HpglSim* plotter = nullptr;
    o.on_pause = [&](const PauseRequest& p) {
      ++asked;
      CHECK(p.line == pause_line);
      CHECK(p.note == "load pen 7 red #ff0000 in slot 1");
      // The plotter has drawn what came before (the streamer waited for it).
      drawn_then = plotter->record().size();
      return PauseAnswer::go;
    };
    HpglRun run(fast(), o);
    plotter = &run.sim;
    StreamResult r = run.st.stream(job, 0, {}, nullptr);
    CHECK(r.completed);
    CHECK(r.pauses == 1);
    CHECK(asked == 1);
    CHECK(drawn_then == before);
    REQUIRE(run.sim.wait_idle(20));
    CHECK(run.sim.stats().errors == 0);  // no CO reached the plotter
    auto d = testjob::compare(job_segments(job), run.sim.record());
    INFO(d.str());
    CHECK(d.equal());
  }
}

TEST_CASE("HPGL pause answered stop: the journal ends before it, or with it as done (stop_after)", "[drivers][hpgl][pause]") {
  std::string first;
  const Job job = parse_hpgl_job(hpgl_with_pause(first));
  long pause_line = -1;
  for (size_t i = 0; i < job.lines.size(); ++i)
    if (job.lines[i].pause) pause_line = static_cast<long>(i);
  test::TempDir t;
  for (const PauseAnswer answer : {PauseAnswer::stop, PauseAnswer::stop_after}) {
    const std::string jpath = t.file(answer == PauseAnswer::stop ? "a.hpgl.journal" : "b.hpgl.journal");
    hpgl::Options o;
    o.on_pause = [&](const PauseRequest&) { return answer; };
    HpglRun run(fast(), o);
    JournalHeader h;
    h.total_lines = job.lines.size();
    {
      Journal journal(jpath, h);
      CHECK_THROWS_WITH(run.st.stream(job, 0, {}, &journal), Catch::Contains("stopped at the pause on line " +
                                                                             std::to_string(pause_line + 1)));
    }
    const JournalState js = Journal::load(jpath);
    CHECK(js.last_acked == (answer == PauseAnswer::stop ? pause_line - 1 : pause_line));
  }
}

TEST_CASE("HPGL: an instruction longer than the plotter's buffer is refused before anything is sent", "[drivers][hpgl][faults]") {
  hpgl::Options o;
  o.buffer_bytes = 64;
  HpglRun run(fast(), o);
  std::string pd = "IN;SP1;PU0,0;PD";
  for (int i = 0; i < 20; ++i) pd += (i ? "," : "") + std::to_string(100 + i * 10) + ",200";
  pd += ";PU;SP0;";
  const Job job = parse_hpgl_job(pd);
  CHECK_THROWS_WITH(run.st.stream(job, 0, {}, nullptr), Catch::Contains("the plotter's buffer can take at once") &&
                                                            Catch::Contains("nothing was sent"));
  REQUIRE(run.sim.wait_idle(5));
  CHECK(run.sim.record().empty());
}

TEST_CASE("HPGL connect clears an unfinished instruction a dead host left, instead of waiting for it", "[drivers][hpgl][faults]") {
  sim::HpglSim sim(fast());
  const std::string path = sim.open_pty();
  {
    PosixSerial dead(path, {});
    dead.write("IN;SP1;PU100,100;PD200,200,300", Millis(1000));  // the host died mid-instruction
  }
  PosixSerial port(path, {});
  hpgl::Options o;
  o.watchdog = Millis(500);
  std::vector<std::string> notes;
  o.log = [&](const std::string& s) { notes.push_back(s); };
  hpgl::Streamer st(port, o);
  const auto t0 = std::chrono::steady_clock::now();
  st.connect();
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5));
  bool cleared = false;
  for (const auto& n : notes) cleared |= n.find("cleared with ESC.K") != std::string::npos;
  CHECK(cleared);
  const Job job = hpgl_job(23, 6);
  CHECK(st.stream(job, 0, {}, nullptr).completed);
}

TEST_CASE("HPGL watchdog: a plotter that frees nothing stops the plot with a clear error and a resumable journal",
          "[drivers][hpgl][faults][watchdog]") {
  sim::Faults f;
  f.stall_line = 10, f.stall_ms = 2e6;
  hpgl::Options o;
  o.watchdog = Millis(600);
  HpglRun run(fast(f), o);
  const Job job = hpgl_job(24, 30);
  test::TempDir t;
  const std::string jpath = t.file("w.hpgl.journal");
  JournalHeader h;
  h.total_lines = job.lines.size();
  const auto t0 = std::chrono::steady_clock::now();
  {
    Journal journal(jpath, h);
    CHECK_THROWS_WITH(run.st.stream(job, 0, {}, &journal), Catch::Contains("took nothing for 0.6 s") &&
                                                                Catch::Contains("the plot stopped"));
  }
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5));
  const JournalState js = Journal::load(jpath);
  CHECK_FALSE(js.complete);
  CHECK(js.last_acked < 10);
}
