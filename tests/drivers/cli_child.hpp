#pragma once
// `stipplot` as a child process the test can signal mid-plot: started with its output in
// files, and a wait until its journal shows the plot under way.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <string>
#include <thread>

#include "drivers/stream/journal.hpp"
#include "util/error.hpp"

extern char** environ;

namespace testjob {

// `stipplot ARGS` as a child with stdout and stderr in files, stdin empty.
inline pid_t spawn_cli(const std::string& args, const std::string& out, const std::string& err) {
  const std::string cmd = "exec " + std::string(STIPPLOT_BIN) + " " + args + " >" + out + " 2>" + err + " </dev/null";
  const char* argv[] = {"sh", "-c", cmd.c_str(), nullptr};
  pid_t pid = 0;
  REQUIRE(::posix_spawn(&pid, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ) == 0);
  return pid;
}

// Waits (at most 60 s) until the journal has acknowledged `line`: true. False if the child
// ended first (its status in `status`, `ended` set) or time ran out.
inline bool wait_for_ack(const std::string& journal, long line, pid_t child, int& status, bool& ended) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < end) {
    if (::waitpid(child, &status, WNOHANG) == child) {
      ended = true;
      return false;
    }
    try {
      if (stipplot::io::Journal::load(journal).last_acked >= line) return true;
    } catch (const stipplot::UserError&) {  // not written yet, or a record under way
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

// Sends `sig` to the child once its journal has acknowledged `line` (SIGKILL if that never
// comes) and reaps it. Returns whether the plot was under way when signalled.
inline bool signal_when_under_way(pid_t child, const std::string& journal, long line, int sig, int& status) {
  bool ended = false;
  const bool under_way = wait_for_ack(journal, line, child, status, ended);
  if (!ended) {
    ::kill(child, under_way ? sig : SIGKILL);
    REQUIRE(::waitpid(child, &status, 0) == child);
  }
  return under_way;
}

}  // namespace testjob
