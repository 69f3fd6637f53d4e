// Host faults: `stipplot plot` itself dies mid-plot (SIGKILL) or is told to stop
// (SIGTERM, SIGHUP), then a second `stipplot plot --resume` finishes the job. The
// plotter is an external `stipplot sim` process on a pty, so it outlives the host as a
// real one does; what it drew (--record-out) is scored as the fault matrix scores it:
// nothing lost, at most one move drawn twice, no stray mark.
#include <sys/wait.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_child.hpp"
#include "compare.hpp"
#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "drivers/job/segments.hpp"
#include "drivers/stream/journal.hpp"
#include "jobgen.hpp"
#include "test_util.hpp"

using namespace stipplot;
using namespace stipplot::io;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// `stipplot sim KIND` in the background: its pid and pty; stop() ends it and returns
// what it drew.
class SimProcess {
 public:
  SimProcess(const std::string& kind, const std::string& record) : record_(record) {
    const std::string cmd = "sh -c 'echo $$; exec " + std::string(STIPPLOT_BIN) + " sim " + kind +
                            " --speedup 40 --record-out " + record + "' 2>/dev/null";
    pipe_ = ::popen(cmd.c_str(), "r");
    REQUIRE(pipe_);
    char line[256];
    REQUIRE(std::fgets(line, sizeof line, pipe_));
    pid_ = std::atoi(line);
    REQUIRE(std::fgets(line, sizeof line, pipe_));
    pty_ = std::string(line).substr(0, std::strlen(line) - 1);
  }
  ~SimProcess() {
    if (pipe_) stop();
  }
  const std::string& pty() const { return pty_; }
  std::vector<Segment> stop() {
    ::kill(pid_, SIGTERM);
    ::pclose(pipe_);
    pipe_ = nullptr;
    std::vector<Segment> rec;
    std::istringstream in(slurp(record_));
    Segment s;
    while (in >> s.x0 >> s.y0 >> s.x1 >> s.y1 >> s.pen) rec.push_back(s);
    return rec;
  }

 private:
  std::string record_, pty_;
  FILE* pipe_ = nullptr;
  pid_t pid_ = 0;
};

struct HostCell {
  size_t lost = 0, doubled = 0, stray = 0;
  int first_status = 0;
  std::string first_err, second_err;
  int second_rc = -1;
};

// Plots `job_text` on a simulator, sends `sig` to the plot a third of the way in, resumes
// with a second plot, and scores what the simulator drew.
HostCell host_cell(const std::string& kind, bool dots, int sig) {
  test::TempDir t;
  const bool hpgl = kind == "hpgl";
  const auto strokes = testjob::random_strokes(dots ? 71 : 72, 40, dots ? 1 : 5);
  const std::string text = hpgl ? testjob::hpgl(strokes) : testjob::gcode(strokes);
  const std::string job = t.file(hpgl ? "m.hpgl" : "m.gcode");
  std::ofstream(job) << text;
  const Job parsed = hpgl ? parse_hpgl_job(text) : parse_gcode_job(text);
  const std::string profile = hpgl ? " --profile hp7475a-a4" : "";
  SimProcess sim(kind, t.file("drawn.txt"));
  HostCell c;
  const pid_t first =
      testjob::spawn_cli("plot " + job + profile + " --port " + sim.pty() + " -q", t.file("out1"), t.file("err1"));
  const bool under_way = testjob::signal_when_under_way(first, Journal::path_for(job),
                                                        static_cast<long>(parsed.lines.size() / 3), sig, c.first_status);
  c.first_err = slurp(t.file("err1"));
  REQUIRE(under_way);
  const auto second = test::run_cli("plot --resume " + job + profile + " --port " + sim.pty());
  c.second_rc = second.exit_code;
  c.second_err = second.err;
  const std::vector<Segment> drawn = sim.stop();
  const auto planned = job_segments(parsed);
  const auto d = testjob::compare(planned, drawn);
  c.lost = d.missing;
  c.doubled = d.duplicated;
  for (const auto& s : drawn)
    if (!testjob::along_planned(s, planned)) ++c.stray;
  return c;
}

const char* signal_name(int sig) { return sig == SIGKILL ? "SIGKILL" : sig == SIGTERM ? "SIGTERM" : "SIGHUP"; }

void check_host_cell(const std::string& kind, bool dots, int sig) {
  const HostCell c = host_cell(kind, dots, sig);
  std::printf("host faults | %-7s | %-4s | %-6s | lost %zu | doubled %zu | stray %zu\n", signal_name(sig), kind.c_str(),
              dots ? "dots" : "stroke", c.lost, c.doubled, c.stray);
  std::fflush(stdout);
  INFO(kind << " " << signal_name(sig) << " " << (dots ? "dots" : "stroke") << "\nfirst plot: " << c.first_err
            << "\nresume: " << c.second_err);
  CHECK(c.second_rc == 0);
  CHECK(c.lost == 0);
  CHECK(c.doubled <= 1);
  CHECK(c.stray == 0);
  if (sig == SIGKILL) {
    CHECK((WIFSIGNALED(c.first_status) && WTERMSIG(c.first_status) == SIGKILL));
    return;
  }
  // Stopped cleanly: a non-zero exit and one line saying how to resume.
  CHECK(WIFEXITED(c.first_status));
  CHECK(WEXITSTATUS(c.first_status) != 0);
  CHECK(c.first_err.find(std::string("stopped by ") + signal_name(sig)) != std::string::npos);
  CHECK(c.first_err.find("--resume") != std::string::npos);
  CHECK(std::count(c.first_err.begin(), c.first_err.end(), '\n') == 1);
}

}  // namespace

TEST_CASE("host faults: grbl, stipplot killed or stopped mid-plot, then --resume: nothing lost, at most one move doubled",
          "[drivers][grbl][faults][host]") {
  for (const int sig : {SIGKILL, SIGTERM, SIGHUP})
    for (const bool dots : {true, false}) check_host_cell("grbl", dots, sig);
}

TEST_CASE("host faults: HPGL, stipplot killed or stopped mid-plot, then --resume: nothing lost, at most one move doubled",
          "[drivers][hpgl][faults][host]") {
  for (const int sig : {SIGKILL, SIGTERM, SIGHUP})
    for (const bool dots : {true, false}) check_host_cell("hpgl", dots, sig);
}
