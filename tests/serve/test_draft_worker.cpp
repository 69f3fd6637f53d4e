// The studio's draft worker: commands run in forks of one started `stipplot`, with the
// same output and exit code as a process of their own; cancelled, and restarted when the
// worker has died.
#include <signal.h>
#include <sys/wait.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <thread>

#include "serve/child.hpp"
#include "serve/draft_worker.hpp"
#include "test_util.hpp"

using namespace stipplot::serve;

namespace {
std::vector<std::string> stipple_args(const std::string& out) {
  return {"stipplot", "stipple", test::example("coffee.png"), "-o", out, "--seed", "4", "--json", "--draft",
          "--preview", out + ".png", "--preview-dpi", "60"};
}

// One draft nobody cancels.
ChildResult run_in(DraftWorker& w, const std::vector<std::string>& args, const test::TempDir& t) {
  DraftWorker::Job job;
  return w.run(args, t.path.string(), job);
}
}  // namespace

TEST_CASE("draft worker: a command's files, output and exit code are those of its own process", "[serve][draft]") {
  test::TempDir t;
  DraftWorker w({STIPPLOT_BIN, kDraftWorkerArg});
  DraftWorker::Job job;
  const ChildResult r = w.run(stipple_args("w.svg"), t.path.string(), job);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK_FALSE(r.cancelled);
  CHECK(last_json_line(r.out).value("primitives", 0) > 10);
  std::vector<std::string> own = stipple_args("c.svg");
  own[0] = STIPPLOT_BIN;
  const ChildResult c = run_child(own, t.path.string());
  REQUIRE(c.exit_code == 0);
  CHECK(test::read_file(t.file("w.svg")) == test::read_file(t.file("c.svg")));
  CHECK(test::read_file(t.file("w.svg.png")) == test::read_file(t.file("c.svg.png")));

  // A user's error: the CLI's one line on stderr, exit 1, and the worker serves on.
  const ChildResult e = run_in(w, {"stipplot", "stipple", "missing.png", "-o", "x.svg"}, t);
  CHECK(e.exit_code == 1);
  CHECK(e.err.find("stipplot: error: missing.png: no such file") != std::string::npos);
  CHECK(run_in(w, stipple_args("again.svg"), t).exit_code == 0);
}

TEST_CASE("draft worker: a cancelled draft ends at once, the next one runs", "[serve][draft]") {
  test::TempDir t;
  DraftWorker w({STIPPLOT_BIN, kDraftWorkerArg});
  REQUIRE(run_in(w, stipple_args("a.svg"), t).exit_code == 0);  // the worker is up
  // A long command (the 4-hour stipple of a photo at full size, seconds of work).
  DraftWorker::Job slow;
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    w.cancel(slow);
  });
  const auto t0 = std::chrono::steady_clock::now();
  const ChildResult r = w.run({"stipplot", "stipple", test::example("coffee.png"), "-o", "slow.svg", "--time", "8h",
                               "--relax", "20"},
                              t.path.string(), slow);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  canceller.join();
  CHECK(r.cancelled);
  CHECK(s < 2.0);
  CHECK_FALSE(std::filesystem::exists(t.file("slow.svg")));
  // A job cancelled before it ran never starts.
  DraftWorker::Job never;
  w.cancel(never);
  CHECK(w.run(stipple_args("never.svg"), t.path.string(), never).cancelled);
  CHECK_FALSE(std::filesystem::exists(t.file("never.svg")));
  CHECK(run_in(w, stipple_args("b.svg"), t).exit_code == 0);
}

TEST_CASE("draft worker: a worker that has died is started again", "[serve][draft]") {
  test::TempDir t;
  DraftWorker w({STIPPLOT_BIN, kDraftWorkerArg});
  REQUIRE(run_in(w, stipple_args("a.svg"), t).exit_code == 0);
  const pid_t dead = w.worker_pid();
  REQUIRE(dead > 0);
  REQUIRE(::kill(dead, SIGKILL) == 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const ChildResult r = run_in(w, stipple_args("b.svg"), t);
  CHECK(r.exit_code == 0);
  CHECK(w.worker_pid() != dead);
  CHECK(std::filesystem::exists(t.file("b.svg")));
}

TEST_CASE("children start with malloc on huge pages, a tunable already set is kept", "[serve]") {
  const ChildResult r = run_child({"/usr/bin/env"});
  CHECK(r.out.find("GLIBC_TUNABLES=") != std::string::npos);
  CHECK(r.out.find("glibc.malloc.hugetlb=1") != std::string::npos);
  ::setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=0", 1);
  const ChildResult kept = run_child({"/usr/bin/env"});
  ::unsetenv("GLIBC_TUNABLES");
  CHECK(kept.out.find("GLIBC_TUNABLES=glibc.malloc.hugetlb=0\n") != std::string::npos);
}
