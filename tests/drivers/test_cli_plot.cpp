// The CLI end to end: `stipplot devices`, `stipplot plot --sim`, and `stipplot sim` on a
// pty with `plot --port`, a disconnect, and `plot --resume`.
#include <signal.h>
#include <sys/wait.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <iterator>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "jobgen.hpp"

namespace fs = std::filesystem;

namespace {

struct Out {
  int rc;
  std::string text;
};

Out run(const std::string& args) {
  std::string cmd = std::string(STIPPLOT_BIN) + " " + args + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  int st = ::pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

fs::path scratch() {
  auto d = fs::temp_directory_path() / ("stipplot-cli-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

std::string write_job(const fs::path& dir, const std::string& name, const std::string& text) {
  auto p = dir / name;
  std::ofstream(p) << text;
  return p.string();
}

}  // namespace

TEST_CASE("stipplot devices runs with no devices and says so", "[cli][drivers]") {
  Out o = run("devices");
  CHECK(o.rc == 0);
  CHECK(o.text.find("Serial ports") != std::string::npos);
  CHECK(o.text.find("USB devices") != std::string::npos);
  Out j = run("devices --json");
  CHECK(j.rc == 0);
  CHECK(nlohmann::json::parse(j.text).contains("plausible"));
}

TEST_CASE("stipplot plot --sim draws exactly the job and writes what it drew", "[cli][drivers]") {
  auto dir = scratch();
  std::string job = write_job(dir, "j.gcode", testjob::gcode(testjob::random_strokes(41, 15, 5)));
  Out o = run("plot " + job + " --sim --sim-speedup 50 --json -q");
  REQUIRE(o.rc == 0);
  auto j = nlohmann::json::parse(o.text.substr(o.text.rfind("{\"command\"")));
  CHECK(j["completed"] == true);
  CHECK(j["sim_exact"] == true);
  CHECK(fs::file_size(j["sim_png"].get<std::string>()) > 1000);
  CHECK(fs::exists(j["sim_svg"].get<std::string>()));
  std::string hp = write_job(dir, "j.hpgl", testjob::hpgl(testjob::random_strokes(42, 10, 5)));
  Out h = run("plot " + hp + " --sim --sim-speedup 50 --json -q");
  REQUIRE(h.rc == 0);
  CHECK(nlohmann::json::parse(h.text.substr(h.text.rfind("{\"command\""))).at("sim_exact") == true);
  Out bad = run("plot " + (dir / "missing.gcode").string() + " --sim");
  CHECK(bad.rc != 0);
  CHECK(bad.text.find("cannot read") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("stipplot sim on a pty: plot --port, a disconnect, plot --resume", "[cli][drivers][resume]") {
  auto dir = scratch();
  std::string job = write_job(dir, "r.gcode", testjob::gcode(testjob::random_strokes(43, 25, 5)));
  std::string cmd = "sh -c 'echo $$; exec " + std::string(STIPPLOT_BIN) + " sim grbl --speedup 40 --disconnect-after 1500 --record-svg " +
                    (dir / "drawn.svg").string() + "' 2>/dev/null";
  FILE* sim = ::popen(cmd.c_str(), "r");
  REQUIRE(sim);
  char line[256];
  REQUIRE(std::fgets(line, sizeof line, sim));
  pid_t pid = std::atoi(line);
  REQUIRE(std::fgets(line, sizeof line, sim));
  std::string pty1 = std::string(line).substr(0, std::strlen(line) - 1);
  Out first = run("plot " + job + " --port " + pty1 + " -q");
  CHECK(first.rc != 0);
  CHECK(first.text.find("disconnected") != std::string::npos);
  CHECK(first.text.find("--resume " + job) != std::string::npos);
  REQUIRE(std::fgets(line, sizeof line, sim));  // the simulator is back on a new pty
  std::string pty2 = std::string(line).substr(0, std::strlen(line) - 1);
  Out second = run("plot --resume " + job + " --port " + pty2 + " --json -q");
  CHECK(second.rc == 0);
  CHECK(second.text.find("\"completed\":true") != std::string::npos);
  ::kill(pid, SIGTERM);
  ::pclose(sim);
  CHECK(fs::exists(dir / "drawn.svg"));
  Out again = run("plot --resume " + job + " --port " + pty2);
  CHECK(again.rc != 0);
  CHECK(again.text.find("already plotted") != std::string::npos);
  fs::remove_all(dir);
}

// A power loss: the port goes with the board, which comes back fresh (banner, position
// zeroed) on a new pty; the resume's result says where it went on from, how much pen-down
// path it may draw again and why, on the human line and in --json.
TEST_CASE("stipplot sim on a pty: a power loss, plot --resume says what it redraws and why", "[cli][drivers][resume][power]") {
  auto dir = scratch();
  std::string job = write_job(dir, "p.gcode", testjob::gcode(testjob::random_strokes(44, 25, 5)));
  std::string cmd = "sh -c 'echo $$; exec " + std::string(STIPPLOT_BIN) + " sim grbl --speedup 10 --power-loss-after 1500' 2>/dev/null";
  FILE* sim = ::popen(cmd.c_str(), "r");
  REQUIRE(sim);
  char line[256];
  REQUIRE(std::fgets(line, sizeof line, sim));
  pid_t pid = std::atoi(line);
  REQUIRE(std::fgets(line, sizeof line, sim));
  std::string pty1 = std::string(line).substr(0, std::strlen(line) - 1);
  Out first = run("plot " + job + " --port " + pty1 + " -q");
  CHECK(first.rc != 0);
  CHECK(first.text.find("--resume " + job) != std::string::npos);
  REQUIRE(std::fgets(line, sizeof line, sim));  // powered on again, on a new pty
  std::string pty2 = std::string(line).substr(0, std::strlen(line) - 1);
  Out second = run("plot --resume " + job + " --port " + pty2 + " --json -q");
  ::kill(pid, SIGTERM);
  ::pclose(sim);
  REQUIRE(second.rc == 0);
  const auto j = nlohmann::json::parse(second.text.substr(second.text.rfind("{\"command\"")));
  CHECK(j["completed"] == true);
  REQUIRE(j.contains("resume"));
  INFO(j["resume"].dump());
  CHECK(j["resume"]["redraw_mm"].get<double>() >= 0);
  CHECK(j["resume"]["why"].get<std::string>().find("last point proved drawn before the loss") != std::string::npos);
  std::printf("CLI resume after a power loss: %s\n", j["resume"].dump().c_str());
  fs::remove_all(dir);
}

TEST_CASE("plot names the pen at start, pause and resume, and without a terminal needs --pen-change", "[cli][drivers][pause]") {
  auto dir = scratch() / "pens";
  fs::create_directories(dir);
  const auto strokes = testjob::random_strokes(46, 8, 4);
  std::string first = testjob::gcode(testjob::Strokes(strokes.begin(), strokes.begin() + 4));
  first.resize(first.rfind("G0 X0 Y0\n"));
  const std::string job = write_job(dir, "pens.gcode",
                                    "; layer 1 pen black (#000000)\n" + first +
                                        "M0 (MSG,Change pen: pen 2 red #ff0000)\n" +
                                        testjob::gcode(testjob::Strokes(strokes.begin() + 4, strokes.end())));
  // No terminal to ask, no --pen-change: refused before any port is opened.
  Out refused = run("plot " + job + " --port /dev/stipplot-no-such-port < /dev/null");
  CHECK(refused.rc != 0);
  CHECK(refused.text.find("--pen-change") != std::string::npos);
  CHECK(refused.text.find("Change pen: pen 2 red #ff0000") != std::string::npos);
  CHECK(refused.text.find("no-such-port") == std::string::npos);
  // stop: the plot stops at the pause, which counts as done; resume names the pen needed.
  Out stopped = run("plot " + job + " --sim --sim-speedup 50 --pen-change stop < /dev/null");
  CHECK(stopped.rc != 0);
  CHECK(stopped.text.find("starting with layer 1 pen black (#000000)") != std::string::npos);
  CHECK(stopped.text.find("stopped at the pause on line") != std::string::npos);
  CHECK(stopped.text.find("--resume") != std::string::npos);
  Out resumed = run("plot --resume " + job + " --sim --sim-speedup 50 --pen-change stop --json < /dev/null");
  CHECK(resumed.rc == 0);
  CHECK(resumed.text.find("resuming with Change pen: pen 2 red #ff0000") != std::string::npos);
  // continue: every pause passed, the simulator draws the whole job.
  Out go = run("plot " + job + " --sim --sim-speedup 50 --pen-change continue --json -q < /dev/null");
  REQUIRE(go.rc == 0);
  auto j = nlohmann::json::parse(go.text.substr(go.text.rfind("{\"command\"")));
  CHECK(j["pauses"] == 1);
  CHECK(j["sim_exact"] == true);
  Out bad = run("plot " + job + " --sim --pen-change maybe < /dev/null");
  CHECK(bad.rc != 0);
  CHECK(bad.text.find("--pen-change must be") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("plot --resume refuses a journal that is damaged or acknowledges beyond the job", "[cli][drivers][journal]") {
  auto dir = scratch() / "journal";
  fs::create_directories(dir);
  const auto strokes = testjob::random_strokes(47, 6, 4);
  std::string first = testjob::gcode(testjob::Strokes(strokes.begin(), strokes.begin() + 3));
  first.resize(first.rfind("G0 X0 Y0\n"));
  const std::string job = write_job(dir, "j.gcode", first + "M0 (MSG,Change pen: pen 2 red #ff0000)\n" +
                                                        testjob::gcode(testjob::Strokes(strokes.begin() + 3, strokes.end())));
  Out stopped = run("plot " + job + " --sim --sim-speedup 50 --pen-change stop -q < /dev/null");
  REQUIRE(stopped.rc != 0);
  const std::string journal = job + ".journal";
  std::string kept;
  {
    std::ifstream in(journal);
    kept.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::ofstream(journal, std::ios::app) << "ack 99999999\n";
  Out forged = run("plot --resume " + job + " --sim -q < /dev/null");
  CHECK(forged.rc != 0);
  CHECK(forged.text.find("fails its checksum") != std::string::npos);
  std::ofstream(journal) << kept;
  std::ofstream(job, std::ios::app) << "G0 X1 Y1\n";  // the job edited since
  Out other = run("plot --resume " + job + " --sim -q < /dev/null");
  CHECK(other.rc != 0);
  CHECK(other.text.find("belongs to another version") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("plot refuses a job file that leaves the profile's travel, naming the line", "[cli][drivers]") {
  auto dir = scratch() / "travel";
  fs::create_directories(dir);
  const std::string job = write_job(dir, "far.gcode", "G21\nG90\nM5\nG0 X10 Y10\nG0 X100000 Y10\nG0 X0 Y0\n");
  Out o = run("plot " + job + " --profile grbl-servo --sim -q < /dev/null");
  CHECK(o.rc != 0);
  CHECK(o.text.find("line 5 `G0 X100000 Y10` goes to (100000, 10) mm, outside the travel of profile grbl-servo") !=
        std::string::npos);
  CHECK(o.text.find("nothing was sent") != std::string::npos);
  CHECK_FALSE(fs::exists(job + ".journal"));
  fs::remove_all(dir);
}

TEST_CASE("plot --port file:PATH writes the job raw: no queries, no reset, done at once", "[cli][drivers]") {
  auto dir = scratch();
  const std::string job = write_job(dir, "s.gcode", testjob::gcode(testjob::random_strokes(44, 12, 5)));
  const std::string out = (dir / "sink.gcode").string();
  const auto t0 = std::chrono::steady_clock::now();
  Out o = run("plot " + job + " --port file:" + out + " --json -q");
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO(o.text);
  REQUIRE(o.rc == 0);
  CHECK(secs < 5);  // nothing waits for an answer that never comes
  std::ifstream in(out, std::ios::binary);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(written.find('?') == std::string::npos);     // no status query
  CHECK(written.find('\x18') == std::string::npos);  // no soft reset
  CHECK(written.find("G1") != std::string::npos);
  const auto j = nlohmann::json::parse(o.text.substr(o.text.rfind("{\"")));
  CHECK(j["answers"] == false);
  CHECK(j["completed"] == true);
  CHECK(!fs::exists(job + ".journal"));
  Out again = run("plot --resume " + job + " --port file:" + out);
  CHECK(again.rc != 0);
  fs::remove_all(dir);
}
