// AxiDraw jobs on the EBB's own firmware (ebb_sim, ebb_sim.hpp): what it drew, rebuilt
// from its step and pen events, against the plan; its motion time against the estimate;
// streaming over a pty with `stipplot plot`, a dropped link and --resume.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

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
  WARN("marks " << cmp.drawn_marks << "/" << cmp.plan_marks << ", worst distance from the job's moves " << as_sent.worst
                << " mm, from the plan " << cmp.worst << " mm; firmware motion ends at " << log.last_step_s
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

TEST_CASE("EBB firmware draws a small stipple on axidraw-minikit as planned, in the estimated time", "[ebb]") {
  test::TempDir t;
    // 102 dots of a tone stipple, drawn as touches and filled discs.
  auto r = test::run_cli("stipple " + test::example("horse.png") + " --page 60x40mm --margin 3 -a 20px -b 40px " +
                         "--profile axidraw-minikit -q -o " + t.file("dots.svg"));
  REQUIRE(r.exit_code == 0);
  const Exported e = export_both("export " + t.file("dots.svg") + " --profile axidraw-minikit", t.file("dots"));
  const std::string replies = ebbtest::run_job_file(e.job, t.file("fw.log"));
  CHECK(replies.find('!') == std::string::npos);
  const ebbtest::SimLog log = ebbtest::read_log(t.file("fw.log"), 80);
  REQUIRE(log.marks.size() > 50);
  check_drawn_as_planned(e, log);
  CHECK(log.last_step_s == Approx(e.estimate_s).epsilon(0.01));
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
  // The host kept the firmware's FIFO fed: its motion took the job's own time.
  CHECK(log.last_step_s - log.first_step_s == Approx(e.estimate_s - 0.130).epsilon(0.01));
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
      auto second = test::run_cli("plot --resume " + e.job + " --port " + port + " --pen-change continue --json -q");
      INFO(first.err << second.err);
      REQUIRE(second.exit_code == 0);
      const auto s = ebb_last_json(second.out);
      CHECK(s["completed"].get<bool>());
      board.finish();
      const ebbtest::SimLog log = ebbtest::read_log(log_path, 80);
      check_drawn_as_planned(e, log);
    }
  }
}

TEST_CASE("EBB bad input: not an EBB, an error reply, a job outside the travel", "[ebb]") {
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

  // Outside the 300 x 218 mm travel: refused before anything is sent.
  const std::string far_job = t.file("far.ebb");
  std::ofstream(far_job) << "EM,1,1\nSP,1,130\nSM,1000,25000,25000\n";
  {
    ebbtest::EbbBoard board(t.file("far.log"));
    r = test::run_cli("plot " + far_job + " --profile axidraw-v3 --port " + board.port());
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("outside the travel") != std::string::npos);
    CHECK(board.commands() == 0);
    board.finish();
  }

  // The firmware refuses a command: "!6 Err: Invalid parameter value" stops the plot.
  const std::string bad_job = t.file("bad.ebb");
  std::ofstream(bad_job) << "EM,1,1\nSC,4,70000\nSP,1,130\nSM,100,800,800\n";
  {
    ebbtest::EbbBoard board(t.file("bad.log"));
    r = test::run_cli("plot " + bad_job + " --profile axidraw-v3 --port " + board.port() + " -q");
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("!6 Err: Invalid parameter value") != std::string::npos);
    board.finish();
    const ebbtest::SimLog log = ebbtest::read_log(t.file("bad.log"), 80);
    CHECK(log.steps == 0);  // stopped before the pen moved
  }
}
