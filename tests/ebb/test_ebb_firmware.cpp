// AxiDraw jobs on the EBB's own firmware (ebb_sim, ebb_sim.hpp): what it drew, rebuilt
// from its step and pen events, against the plan; its motion time against the estimate;
// streaming over a pty with `stipplot plot`, a dropped link and --resume.
#include <catch2/catch.hpp>
#include <algorithm>

#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <nlohmann/json.hpp>

#include "drivers/device/profile.hpp"
#include "drivers/job/ebb_reader.hpp"
#include "drivers/job/timed_job.hpp"
#include "drivers/motion/ebb_motion.hpp"
#include "drivers/stream/ebb/reset.hpp"
#include "drivers/stream/ebb/streamer.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "ebb/ebb_sim.hpp"
#include "test_util.hpp"

namespace {

nlohmann::json ebb_last_json(const std::string& out) {
  const auto end = out.find_last_not_of('\n');
  if (end == std::string::npos) return {};
  const auto start = out.rfind('\n', end);
  const size_t from = start == std::string::npos ? 0 : start + 1;
  try {
    return nlohmann::json::parse(out.substr(from, end + 1 - from));
  } catch (const nlohmann::json::exception&) {
    return {};
  }
}

struct Exported {
  std::string job, plan;
  double estimate_s = 0;
};

// `stipplot ARGS -o OUT.ebb` and the same plan as an SVG (the planner is deterministic).
Exported export_both(const std::string& args, const std::string& out) {
  auto r = test::run_cli(args + " -o " + out + ".ebb --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  Exported e{out + ".ebb", out + ".plan.svg", ebb_last_json(r.out)["plan"]["total"]["seconds"].get<double>()};
  REQUIRE(test::run_cli(args + " -q -o " + e.plan).exit_code == 0);
  return e;
}

// `plot --resume JOB --port PORT --pen-change continue --json` run to its end (it must
// complete): its summary, and what it said (the resume's note; `quiet` adds -q). `before`
// is what the interrupted run said, for a failure's message.
struct Resumed {
  nlohmann::json summary;
  std::string err;
};
Resumed resume_to_end(const std::string& job, const std::string& port, const std::string& before, bool quiet = true) {
  auto r = test::run_cli("plot --resume " + job + " --port " + port + " --pen-change continue --json" + (quiet ? " -q" : ""));
  INFO(before << r.err);
  REQUIRE(r.exit_code == 0);
  Resumed out{ebb_last_json(r.out), r.err};
  CHECK(out.summary["completed"].get<bool>());
  return out;
}

// A motor step moves the pen 1/160 mm along x and along y (80 steps/mm of x + y and of
// x - y): a pen within one step of a line on both motors is within 0.0125 mm of it.
constexpr double kStep = 0.0125;

// Every mark once, in order: within one step of the job's SM moves (the firmware steps each
// motor at its own constant rate, so between the ends of a move either motor may lag the
// straight line by up to a step), and within one and a half steps of the plan (the job's
// move ends are the plan's points rounded to whole motor steps: half a step more).
void check_drawn_as_planned(const Exported& e, const ebbtest::SimLog& log) {
  const auto job = ebbtest::job_marks(e.job, 80);
  const auto as_sent = ebbtest::compare_marks(job, log.marks, kStep);
  INFO(as_sent.why << "; worst " << as_sent.worst << " mm from the job's moves over " << as_sent.plan_marks << " marks");
  CHECK(as_sent.ok);
  const auto plan = ebbtest::planned_strokes(e.plan);
  const auto cmp = ebbtest::compare_marks(plan, log.marks, 1.5 * kStep);
  INFO(cmp.why << "; worst " << cmp.worst << " mm from the plan over " << cmp.plan_marks << " marks");
  CHECK(cmp.ok);
  CHECK(log.m1 == 0);  // back home, to the step
  CHECK(log.m2 == 0);
  // Nothing drawn twice or left out: the pen-down steps are the job's, to the step.
  CHECK(log.down_steps == ebbtest::job_down_steps(e.job));
  WARN("marks " << cmp.drawn_marks << "/" << cmp.plan_marks << ", worst distance from the job's moves " << as_sent.worst
                << " mm, from the plan " << cmp.worst << " mm; pen-down steps " << log.down_steps << " (job "
                << ebbtest::job_down_steps(e.job) << "); firmware motion ends at " << log.last_step_s
                << " s, estimate " << e.estimate_s << " s");
}

}  // namespace

TEST_CASE("EBB firmware draws foreign.svg on axidraw-v3 as planned, in the estimated time", "[ebb]") {
  test::TempDir t;
  const Exported e = export_both("export " + test::example("foreign.svg") + " --profile axidraw-v3", t.file("foreign"));
  const std::string replies = ebbtest::run_job_file(e.job, t.file("fw.log"));
  CHECK(replies.find('!') == std::string::npos);  // no error reply
  const ebbtest::SimLog log = ebbtest::read_log(t.file("fw.log"), 80);
  check_drawn_as_planned(e, log);
  // Commands fed back to back keep the FIFO full: the firmware's time is the job's own.
  CHECK(log.last_step_s == Approx(e.estimate_s).epsilon(0.01));
}

TEST_CASE("EBB firmware draws a small stipple on axidraw-minikit as planned, in the estimated time, as LM and as SM moves", "[ebb]") {
  test::TempDir t;
    // A 3-minute tone stipple: 269 dots, most of them filled discs (spirals), two touches.
  auto r = test::run_cli("stipple " + test::example("horse.png") + " --page 60x40mm --margin 3 --time 3min " +
                         "--profile axidraw-minikit -q -o " + t.file("dots.svg"));
  REQUIRE(r.exit_code == 0);
  struct Run {
    size_t commands = 0;
    double firmware_s = 0, estimate_s = 0;
  };
  std::map<std::string, Run> runs;
  for (const std::string moves : {"lm", "sm"}) {
    INFO("--ebb-moves " << moves);
    const Exported e = export_both("export " + t.file("dots.svg") + " --profile axidraw-minikit --ebb-moves " + moves,
                                   t.file("dots-" + moves));
    const std::string text = test::read_file(e.job);
    CHECK(text.find(moves == "lm" ? "\nLM," : "\nSM,") != std::string::npos);
    CHECK(text.find(moves == "lm" ? "\nSM," : "\nLM,") == std::string::npos);  // no fallback SM
    const std::string replies = ebbtest::run_job_file(e.job, t.file("fw-" + moves + ".log"));
    CHECK(replies.find('!') == std::string::npos);
    const ebbtest::SimLog log = ebbtest::read_log(t.file("fw-" + moves + ".log"), 80);
    REQUIRE(log.marks.size() > 200);
    check_drawn_as_planned(e, log);
    CHECK(log.last_step_s == Approx(e.estimate_s).epsilon(0.01));
    runs[moves] = {static_cast<size_t>(std::count(text.begin(), text.end(), '\n')), log.last_step_s, e.estimate_s};
  }
  for (const auto& [moves, run] : runs)
    WARN(moves << ": " << run.commands << " commands, firmware " << run.firmware_s << " s, estimate " << run.estimate_s
               << " s (" << 100 * (run.estimate_s - run.firmware_s) / run.firmware_s << " %)");
  // The stipple's discs are spirals of short segments, each a speed saw-tooth the LMs
  // follow (an SM has one constant rate for it): a few more commands, not many.
  CHECK(runs["lm"].commands < 1.3 * runs["sm"].commands);
}

TEST_CASE("A long job of many LM moves ends exactly on its planned step position on the firmware, in its time", "[ebb]") {
  // 1,000 random hops and jittery strokes (segments of 0.01 to 0.6 mm), each from rest to rest, as the
  // writer cuts them: the firmware's counters must end where the last point rounds to.
  test::TempDir t;
  const stipplot::DeviceProfile p = stipplot::find_profile("axidraw-v3");
  const stipplot::motion::EbbGeometry g{80};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> coord(0, 60), jitter(-0.3, 0.3);
  stipplot::motion::MotorSteps at{0, 0};
  int64_t clock = 0;
  std::vector<stipplot::motion::MotionBlock> blocks;
  std::vector<stipplot::motion::EbbMove> moves;
  std::string job = "EM,1,1\n";
  stipplot::Vec2 here{0, 0};
  size_t lms = 0;
  for (int i = 0; i < 1000; ++i) {
    std::vector<stipplot::Vec2> pts{here};
    const int n = 1 + i % 4;
    for (int k = 0; k < n; ++k) {
      const stipplot::Vec2 q = i % 5 == 0 ? stipplot::Vec2{coord(rng), coord(rng)}
                                          : stipplot::Vec2{std::clamp(pts.back().x + jitter(rng) * (k + 1), 0.0, 60.0),
                                                           std::clamp(pts.back().y + jitter(rng), 0.0, 60.0)};
      pts.push_back(q);
    }
    moves.clear();
    stipplot::motion::polyline_moves(pts, i % 2 ? p.motion.speed_up_mm_s : p.motion.speed_down_mm_s, p.motion, g, {}, at, clock,
                                     blocks, moves);
    for (const auto& m : moves) {
      job += stipplot::motion::ebb_command(m) + "\n";
      lms += m.lm;
    }
    here = pts.back();
  }
  REQUIRE(at == g.steps(here));
  std::ofstream(t.file("long.ebb")) << job;
  const std::string replies = ebbtest::run_job_file(t.file("long.ebb"), t.file("fw.log"));
  CHECK(replies.find('!') == std::string::npos);
  const ebbtest::SimLog log = ebbtest::read_log(t.file("fw.log"), 80);
  CHECK(log.m1 == at[0]);  // to the step
  CHECK(log.m2 == at[1]);
  const stipplot::io::JobTiming timing = stipplot::io::time_ebb_job(stipplot::io::parse_ebb_job(job, 80));
  CHECK(timing.total_s == Approx(static_cast<double>(clock) / 25000).epsilon(1e-9));
  CHECK(log.last_step_s == Approx(timing.total_s).epsilon(0.001));
  WARN(lms << " LMs of " << std::count(job.begin(), job.end(), '\n') - 1 << " moves end at motor steps " << log.m1 << ","
           << log.m2 << " (planned " << at[0] << "," << at[1] << "); firmware " << log.last_step_s
           << " s, estimate " << timing.total_s << " s");
}

TEST_CASE("stipplot plot streams foreign.svg to the EBB firmware over a pty", "[ebb]") {
  test::TempDir t;
  const Exported e = export_both("export " + test::example("foreign.svg") + " --profile axidraw-v3", t.file("foreign"));
  ebbtest::EbbBoard board(t.file("fw.log"));
  auto r = test::run_cli("plot " + e.job + " --profile axidraw-v3 --port " + board.port() + " --pen-change continue --json -q");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto s = ebb_last_json(r.out);
  CHECK(s["completed"].get<bool>());
  CHECK(s["firmware"].get<std::string>().find("3.0.2") != std::string::npos);
  board.finish();
  const ebbtest::SimLog log = ebbtest::read_log(t.file("fw.log"), 80);
  check_drawn_as_planned(e, log);
  // The host kept the firmware's FIFO fed: its motion took the job's own time, and no more
  // than the same commands fed at once (the FIFO never waiting for the host) but for 0.5 %.
  CHECK(log.last_step_s - log.first_step_s == Approx(e.estimate_s - 0.130).epsilon(0.01));
  ebbtest::run_job_file(e.job, t.file("fed.log"));
  const ebbtest::SimLog fed = ebbtest::read_log(t.file("fed.log"), 80);
  const double starved = (log.last_step_s - log.first_step_s) - (fed.last_step_s - fed.first_step_s);
  WARN("streamed over the pty: motion " << log.last_step_s - log.first_step_s << " s, fed at once "
                                        << fed.last_step_s - fed.first_step_s << " s: the FIFO waited " << starved
                                        << " s for the host");
  // (The simulation runs about 80 times faster than the wall clock here, so a host pause
  // of a few ms empties the 32-command FIFO; real time is measured below.)
  CHECK(starved < 0.01 * (fed.last_step_s - fed.first_step_s));
}

// [realtime] too: it runs in the real-time phase (scripts/test.sh), not beside the other
// tests at nice 10, where on a slow machine the firmware's process once fell 50 ms behind.
TEST_CASE("The EBB's FIFO never waits for the host: 2,000 short segments streamed in real time", "[ebb][realtime]") {
  test::TempDir t;
  // A spiral of 2,000 segments of 0.25 mm (one stroke, about 10 s at 50 mm/s).
  std::string pts;
  double a = 0;
  for (int i = 0; i <= 2000; ++i) {
    const double r = 5 + 0.8 * a / (2 * M_PI);
    pts += std::to_string(30 + r * std::cos(a)) + "," + std::to_string(30 + r * std::sin(a)) + " ";
    a += 0.25 / r;
  }
  std::ofstream(t.file("spiral.svg")) << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"60mm\" height=\"60mm\" "
                                         "viewBox=\"0 0 60 60\"><polyline fill=\"none\" stroke=\"black\" points=\""
                                      << pts << "\"/></svg>\n";
  const Exported e = export_both("export " + t.file("spiral.svg") + " --profile axidraw-v3 --simplify 0", t.file("spiral"));
  ebbtest::EbbBoard board(t.file("fw.log"), true);
  auto r = test::run_cli("plot " + e.job + " --profile axidraw-v3 --port " + board.port() + " -q");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  board.finish();
  ebbtest::run_job_file(e.job, t.file("fed.log"));
  const ebbtest::SimLog live = ebbtest::read_log(t.file("fw.log"), 80), fed = ebbtest::read_log(t.file("fed.log"), 80);
  check_drawn_as_planned(e, live);
  REQUIRE(ebbtest::planned_strokes(e.plan).front().size() > 1500);
  const double starved = (live.last_step_s - live.first_step_s) - (fed.last_step_s - fed.first_step_s);
  WARN("real time: motion " << live.last_step_s - live.first_step_s << " s, fed at once "
                            << fed.last_step_s - fed.first_step_s << " s: the FIFO waited " << starved << " s");
  CHECK(std::fabs(starved) < 0.005);  // under a fifth of one 25 ms slice in all
}

TEST_CASE("EBB streamer reads both reply syntaxes of firmware 3.0.2: legacy OK and CU,10,1", "[ebb]") {
  const std::string text = "EM,1,1\nSP,1,130\nSM,100,800,800\nSP,0,146\nSM,100,800,0\nSP,1,130\nSM,200,-1600,-800\n";
  const stipplot::io::Job job = stipplot::io::parse_ebb_job(text, 80);
  for (bool standardized : {false, true}) {
    DYNAMIC_SECTION((standardized ? "standardized" : "legacy")) {
      test::TempDir t;
      ebbtest::EbbBoard board(t.file("fw.log"));
      stipplot::io::PosixSerial port(board.port(), {});
      stipplot::io::ebb::Options o;
      o.standardized = standardized;
      stipplot::io::ebb::Streamer st(port, o);
      st.connect();
      CHECK(st.firmware().major == 3);
      CHECK(st.position() == std::array<int64_t, 2>{0, 0});
      const auto res = st.stream(job, 0, {}, nullptr);
      CHECK(res.completed);
      CHECK(res.lines_acked == job.lines.size());
      CHECK(st.idle());
      CHECK(st.position() == std::array<int64_t, 2>{0, 0});
      CHECK(st.pen_up());
      CHECK_THROWS_WITH(st.command("SC,4,70000"), Catch::Contains("!6 Err"));
      port.close();
      board.finish();
      const ebbtest::SimLog log = ebbtest::read_log(t.file("fw.log"), 80);
      REQUIRE(log.marks.size() == 1);
      CHECK(log.steps == 1600 + 800 + 2400);
    }
  }
}

TEST_CASE("A dropped link mid-plot, then plot --resume on the powered EBB, loses nothing", "[ebb]") {
  test::TempDir t;
  const Exported e = export_both("export " + test::example("foreign.svg") + " --profile axidraw-v3", t.file("foreign"));
  for (double share : {0.25, 0.5, 0.75}) {
    DYNAMIC_SECTION("dropped at " << share * 100 << " %") {
      const std::string log_path = t.file("fw-" + std::to_string(static_cast<int>(share * 100)) + ".log");
      ebbtest::EbbBoard board(log_path);
      const size_t lines = static_cast<size_t>(test::count_lines(test::read_file(e.job)));
      // connect() sends V, CU,10,0 and CU,4: the job's lines follow.
      board.drop_after_commands(3 + static_cast<size_t>(share * static_cast<double>(lines)));
      auto first = test::run_cli("plot " + e.job + " --profile axidraw-v3 --port " + board.port() + " --pen-change continue -q");
      CHECK(first.exit_code != 0);
      REQUIRE(board.dropped());
      const std::string port = board.reconnect();
      resume_to_end(e.job, port, first.err);
      board.finish();
      const ebbtest::SimLog log = ebbtest::read_log(log_path, 80);
      check_drawn_as_planned(e, log);
    }
  }
}

// ebb_sim's buttons read released, so the rig presses PRG for it: the firmware's answer to
// the first QB after the press reaches stipplot as "1" (EbbBoard::press_button_after_commands).
// Pressed from the start, the first QB (asked once the first move is answered) says so, with
// the stroke under way: the pen is lifted where the board stops and put down there again.
TEST_CASE("The board's PRG button pauses a plot as axicli's does, and plot --resume draws the rest, each mark once", "[ebb]") {
  test::TempDir t;
  const Exported e = export_both("export " + test::example("foreign.svg") + " --profile axidraw-v3", t.file("foreign"));
  ebbtest::EbbBoard board(t.file("fw.log"));
  board.press_button_after_commands(1);
  auto first = test::run_cli("plot " + e.job + " --profile axidraw-v3 --port " + board.port() + " --pen-change continue -q");
  INFO(first.err);
  CHECK(first.exit_code != 0);
  CHECK(board.button_reported());
  CHECK(first.err.find("PRG button") != std::string::npos);
  CHECK(first.err.find("--resume") != std::string::npos);
  CHECK(std::count(first.err.begin(), first.err.end(), '\n') == 1);
  resume_to_end(e.job, board.port(), first.err);
  board.finish();
  // The first QB goes out once the first move is answered; an LM job's travel to its first
  // stroke is a few commands, so the stop may come inside that stroke: the pen lifts there
  // and the resume lowers it again, one mark in two pieces. Judged as ink: every point of
  // the job's pen-down paths within a step of ink and no ink off them, the pen-down steps
  // the job's exactly (nothing drawn twice), back home.
  const ebbtest::SimLog log = ebbtest::read_log(t.file("fw.log"), 80);
  const auto planned = ebbtest::job_marks(e.job, 80);
  CHECK(ebbtest::farthest(planned, log.marks, 0.01, 0.5).worst <= kStep);
  CHECK(ebbtest::farthest(log.marks, planned, 0.01, 0.5).worst <= kStep);
  CHECK(log.down_steps == ebbtest::job_down_steps(e.job));
  CHECK(log.marks.size() <= planned.size() + 1);
  CHECK(log.m1 == 0);
  CHECK(log.m2 == 0);
}

TEST_CASE("A plot resumed twice (the link dropped at 30 % and again at 70 %) still draws each mark once", "[ebb]") {
  test::TempDir t;
  const Exported e = export_both("export " + test::example("foreign.svg") + " --profile axidraw-v3", t.file("foreign"));
  ebbtest::EbbBoard board(t.file("fw.log"));
  const size_t lines = static_cast<size_t>(test::count_lines(test::read_file(e.job)));
  board.drop_after_commands(3 + lines * 3 / 10);
  auto first = test::run_cli("plot " + e.job + " --profile axidraw-v3 --port " + board.port() + " --pen-change continue -q");
  CHECK(first.exit_code != 0);
  REQUIRE(board.dropped());
  std::string port = board.reconnect();
  // The resume's own queries (V, CU, QG, QS, QP, ...) come first: the drop lands in its job lines.
  board.drop_after_commands(board.commands() + lines * 4 / 10);
  auto second = test::run_cli("plot --resume " + e.job + " --port " + port + " --pen-change continue -q");
  INFO(first.err << second.err);
  CHECK(second.exit_code != 0);
  REQUIRE(board.dropped());
  port = board.reconnect();
  resume_to_end(e.job, port, first.err + second.err);
  board.finish();
  check_drawn_as_planned(e, ebbtest::read_log(t.file("fw.log"), 80));
}

TEST_CASE("The host killed (SIGKILL) mid-plot, then plot --resume on the powered EBB, loses nothing", "[ebb]") {
  test::TempDir t;
  const Exported e = export_both("export " + test::example("foreign.svg") + " --profile axidraw-v3", t.file("foreign"));
  ebbtest::EbbBoard board(t.file("fw.log"));
  const size_t lines = static_cast<size_t>(test::count_lines(test::read_file(e.job)));
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_RDWR);
    ::dup2(null, 0), ::dup2(null, 1), ::dup2(null, 2);
    ::execl(STIPPLOT_BIN, STIPPLOT_BIN, "plot", e.job.c_str(), "--profile", "axidraw-v3", "--port", board.port().c_str(),
            "--pen-change", "continue", "-q", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  REQUIRE(pid > 0);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (board.commands() < lines / 2 && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  ::kill(pid, SIGKILL);
  int st = 0;
  ::waitpid(pid, &st, 0);
  REQUIRE(WIFSIGNALED(st));  // killed mid-plot, not finished
  const std::string port = board.reconnect();
  resume_to_end(e.job, port, "");
  board.finish();
  check_drawn_as_planned(e, ebbtest::read_log(t.file("fw.log"), 80));
}

TEST_CASE("A board reset mid-plot (30 and 70 %), then plot --resume from home: every mark drawn", "[ebb]") {
  test::TempDir t;
  const Exported e = export_both("export " + test::example("foreign.svg") + " --profile axidraw-v3", t.file("foreign"));
  const auto planned = ebbtest::job_marks(e.job, 80);
  const size_t planned_steps = ebbtest::job_down_steps(e.job);
  // A stroke's worth: the longest mark's pen-down motor steps (|motor 1| + |motor 2|).
  size_t longest = 0;
  for (const auto& m : planned) {
    size_t n = 0;
    for (size_t i = 1; i < m.size(); ++i)
      n += static_cast<size_t>(std::llround(80 * std::fabs(m[i].x - m[i - 1].x + m[i].y - m[i - 1].y)) +
                               std::llround(80 * std::fabs(m[i].x - m[i - 1].x - m[i].y + m[i - 1].y)));
    longest = std::max(longest, n);
  }
  const stipplot::io::Job parsed = stipplot::io::parse_ebb_job(test::read_file(e.job), 80);
  const size_t lines = static_cast<size_t>(test::count_lines(test::read_file(e.job)));
  for (double share : {0.3, 0.7}) {
    DYNAMIC_SECTION("reset at " << share * 100 << " %") {
      const std::string log_path = t.file("fw-" + std::to_string(static_cast<int>(share * 100)) + ".log");
      ebbtest::EbbBoard board(log_path);
      // connect() sends V, CU,10,0 and CU,4: the job's lines follow (with a QS now and then).
      // The board reboots there (RB): counters at 0, FIFO lost, the link gone. In the sim
      // the carriage is the counters, so it is back home: the premise of the resume below
      // (on a real board the carriage stays where it stopped and is brought home by hand).
      board.reset_after_commands(3 + static_cast<size_t>(share * static_cast<double>(lines)));
      auto first = test::run_cli("plot " + e.job + " --profile axidraw-v3 --port " + board.port() + " --pen-change continue -q");
      CHECK(first.exit_code != 0);
      REQUIRE(board.dropped());
      // What the first run proved lies on the path of the line it names.
      const stipplot::io::JournalState js = stipplot::io::Journal::load(e.job + ".journal");
      CHECK(js.proven.line >= 0);
      if (js.proven.line >= 0)
        CHECK(stipplot::io::ebb::on_sm_path(parsed, static_cast<size_t>(js.proven.line),
                                            stipplot::io::ebb_motor_steps(js.proven.x, js.proven.y, 80), 80));
      const std::string port = board.reconnect();
      const Resumed second = resume_to_end(e.job, port, first.err, false);
      const auto& s = second.summary;
      CHECK(second.err.find("the board was reset") != std::string::npos);
      CHECK(second.err.find("the carriage is taken to be at home") != std::string::npos);
      CHECK(s["resume"]["note"].get<std::string>().find("taken to be at home") != std::string::npos);
      board.finish();
      const ebbtest::SimLog log = ebbtest::read_log(log_path, 80);
      // Nothing lost: every point of the job's pen-down paths has ink within two motor
      // steps, from one run or the other; and no ink off them.
      const auto lost = ebbtest::farthest(planned, log.marks, 0.01, 0.5);
      INFO("farthest from ink: " << lost.worst << " mm at " << lost.where.x << "," << lost.where.y);
      CHECK(lost.worst <= 2 * kStep);
      const auto stray = ebbtest::farthest(log.marks, planned, 0.01, 0.5);
      INFO("stray ink: " << stray.worst << " mm at " << stray.where.x << "," << stray.where.y);
      CHECK(stray.worst <= 2 * kStep);
      // Drawn twice: what the lost FIFO held, at most a stroke's worth, within what the
      // resume said it might redraw (a mm of path is at most 160 motor steps).
      REQUIRE(log.down_steps >= planned_steps);
      const size_t twice = log.down_steps - planned_steps;
      const double redraw_mm = s["resume"]["redraw_mm"].get<double>();
      CHECK(twice <= longest);
      CHECK(static_cast<double>(twice) <= 160 * redraw_mm + 2);
      CHECK(log.m1 == 0);  // back home, to the step
      CHECK(log.m2 == 0);
      WARN("reset at " << share * 100 << " %: resumed at line " << s["resume"]["from_line"] << " of " << lines << " ("
                       << s["resume"]["why"].get<std::string>() << "); pen-down steps " << log.down_steps << " (job "
                       << planned_steps << "): " << twice << " drawn twice (" << twice / 160.0 << "-" << twice / 113.1
                       << " mm; the longest stroke " << longest << " steps; redraw bound " << redraw_mm
                       << " mm); farthest job point from ink " << lost.worst << " mm, stray ink " << stray.worst << " mm");
    }
  }
}

TEST_CASE("A board reset at a pen-change pause, then plot --resume: from the QS proof, each mark once", "[ebb]") {
  test::TempDir t;
  const Exported e = export_both("export " + test::example("foreign.svg") + " --profile axidraw-v3", t.file("foreign"));
  ebbtest::EbbBoard board(t.file("fw.log"));
  // Stopped at the pen change (counted as done): the board ran out its FIFO and the host
  // proved with a QS where it stands.
  auto first = test::run_cli("plot " + e.job + " --profile axidraw-v3 --port " + board.port() + " --pen-change stop -q");
  CHECK(first.exit_code != 0);
  // The board switched off and on during the pen change: counters at 0 and, the sim's
  // carriage being its counters, the carriage at home, as the resume takes it to be.
  board.reboot();
  const std::string port = board.reconnect();
  const Resumed second = resume_to_end(e.job, port, first.err, false);
  const auto& s = second.summary;
  CHECK(second.err.find("the carriage is taken to be at home") != std::string::npos);
  // From the line after the pause, not from the 33 commands the FIFO might have held.
  const std::string text = test::read_file(e.job);
  const size_t pause_line = static_cast<size_t>(test::count_lines(text.substr(0, text.find("# pause:")))) + 1;
  CHECK(s["resume"]["from_line"].get<size_t>() == pause_line + 1);
  CHECK(s["resume"]["why"].get<std::string>().find("proved drawn") != std::string::npos);
  CHECK(s["resume"]["redraw_mm"].get<double>() == 0);
  board.finish();
  check_drawn_as_planned(e, ebbtest::read_log(t.file("fw.log"), 80));  // each mark once, to the step
  WARN("reset at the pause (line " << pause_line << "): resumed at line " << s["resume"]["from_line"] << ", "
                                   << s["resume"]["why"].get<std::string>());
}

TEST_CASE("A reset board resumed from a proof inside a stroke: the split SM draws its rest exactly", "[ebb]") {
  test::TempDir t;
  const Exported e = export_both("export " + test::example("foreign.svg") + " --profile axidraw-v3", t.file("foreign"));
  const std::string text = test::read_file(e.job);
  const stipplot::io::Job job = stipplot::io::parse_ebb_job(text, 80);
  ebbtest::EbbBoard board(t.file("fw.log"));
  auto first = test::run_cli("plot " + e.job + " --profile axidraw-v3 --port " + board.port() + " --pen-change stop -q");
  CHECK(first.exit_code != 0);  // at the pause, the board idle at the end of layer 1's last stroke
  // A proof half-way along one of that stroke's last SMs (the board passed there: a true
  // one, as a QS while the FIFO ran out would give), journalled as the streamer does.
  size_t pause = 0;
  while (!job.lines[pause].pause) ++pause;
  size_t k = pause;
  auto steps_of = [&](size_t i) { return stipplot::io::parse_ebb_command(job.lines[i].text, i + 1); };
  while (--k > pause - 25)
    if (job.lines[k].motion && job.lines[k].pen_down && std::llabs(steps_of(k).s1) + std::llabs(steps_of(k).s2) >= 40) break;
  REQUIRE(k > pause - 25);
  const auto p0 = stipplot::io::ebb::steps_after(job, static_cast<long>(k) - 1, 80);
  const auto sm = steps_of(k);
  const stipplot::io::ebb::Steps q{p0[0] + sm.s1 / 2, p0[1] + sm.s2 / 2};
  char rec[128];
  std::snprintf(rec, sizeof rec, "pos %zu %.4f %.4f 0.0000", k, static_cast<double>(q[0] + q[1]) / 160,
                static_cast<double>(q[0] - q[1]) / 160);
  std::ofstream(e.job + ".journal", std::ios::app) << stipplot::io::Journal::record(rec) << "\n";
  board.reboot();  // switched off and on: counters at 0, the (sim's) carriage home
  const std::string port = board.reconnect();
  const Resumed second = resume_to_end(e.job, port, first.err, false);
  const auto& s = second.summary;
  CHECK(s["resume"]["why"].get<std::string>().find("split") != std::string::npos);
  CHECK(s["resume"]["from_line"].get<size_t>() == k + 2);  // the line after the split one
  board.finish();
  const ebbtest::SimLog log = ebbtest::read_log(t.file("fw.log"), 80);
  const auto planned = ebbtest::job_marks(e.job, 80);
  const auto lost = ebbtest::farthest(planned, log.marks, 0.01, 0.5);
  CHECK(lost.worst <= 2 * kStep);
  const auto stray = ebbtest::farthest(log.marks, planned, 0.01, 0.5);
  CHECK(stray.worst <= 2 * kStep);
  // Drawn twice: the split SM's rest and the stroke's moves after it, to the step (then
  // the pen went up for the pause).
  size_t rest = static_cast<size_t>(std::llabs(sm.s1 - sm.s1 / 2) + std::llabs(sm.s2 - sm.s2 / 2));
  for (size_t i = k + 1; i < pause; ++i)
    if (job.lines[i].motion && job.lines[i].pen_down)
      rest += static_cast<size_t>(std::llabs(steps_of(i).s1) + std::llabs(steps_of(i).s2));
  CHECK(log.down_steps == ebbtest::job_down_steps(e.job) + rest);
  CHECK(log.m1 == 0);
  CHECK(log.m2 == 0);
  WARN("split SM on line " << k + 1 << " (" << job.lines[k].text << ") at its half: " << rest
                           << " pen-down steps drawn again (its rest and the stroke's end), as planned; farthest job point from ink " << lost.worst
                           << " mm, stray ink " << stray.worst << " mm");
}

TEST_CASE("EBB bad input: a port where no EBB answers V is refused", "[ebb]") {
  test::TempDir t;
  // A port where nothing answers V.
  const int m = ::posix_openpt(O_RDWR | O_NOCTTY);
  REQUIRE(m >= 0);
  REQUIRE(::grantpt(m) == 0);
  REQUIRE(::unlockpt(m) == 0);
  const std::string silent = ::ptsname(m);
  const std::string ok_job = t.file("ok.ebb");
  std::ofstream(ok_job) << "EM,1,1\nSP,1,130\nSM,100,800,800\nSP,0,146\nSM,100,800,0\nSP,1,130\nSM,200,-1600,-800\n";
  auto r = test::run_cli("plot " + ok_job + " --profile axidraw-v3 --port " + silent + " -q");
  ::close(m);
  INFO(r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("does not answer V as an EiBotBoard") != std::string::npos);
  CHECK(test::count_lines(r.err) == 1);
}

TEST_CASE("EBB bad input: a job outside the travel is refused before anything is sent", "[ebb]") {
  test::TempDir t;
  // Outside the 300 x 218 mm travel.
  const std::string far_job = t.file("far.ebb");
  std::ofstream(far_job) << "EM,1,1\nSP,1,130\nSM,1000,25000,25000\n";
  {
    ebbtest::EbbBoard board(t.file("far.log"));
    auto r = test::run_cli("plot " + far_job + " --profile axidraw-v3 --port " + board.port());
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("outside the travel") != std::string::npos);
    CHECK(board.commands() == 0);
    board.finish();
  }
}

TEST_CASE("EBB bad input: an error reply stops the plot before the pen moves", "[ebb]") {
  test::TempDir t;
  // The firmware refuses a command: "!6 Err: Invalid parameter value".
  const std::string bad_job = t.file("bad.ebb");
  std::ofstream(bad_job) << "EM,1,1\nSC,4,70000\nSP,1,130\nSM,100,800,800\n";
  {
    ebbtest::EbbBoard board(t.file("bad.log"));
    auto r = test::run_cli("plot " + bad_job + " --profile axidraw-v3 --port " + board.port() + " -q");
    INFO(r.err);
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("!6 Err: Invalid parameter value") != std::string::npos);
    board.finish();
    const ebbtest::SimLog log = ebbtest::read_log(t.file("bad.log"), 80);
    CHECK(log.steps == 0);  // stopped before the pen moved
  }
}
