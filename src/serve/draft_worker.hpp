#pragma once
// Drafts without a program start. While a control moves, the studio draws several times a
// second, and each new `stipplot` process spends ~30 ms loading and linking its libraries
// before it draws: as long as the draft of a reduced photo itself. The draft worker is one
// `stipplot` the studio starts once; for each draft it forks a copy of itself, already
// loaded, which runs the command line and exits. A draft is still a process of its own:
// a crash ends that draft only, a superseded one is killed, and its output is the same
// command's. Full previews, downloads and plots keep their own started processes.
//
// The link is a SOCK_SEQPACKET socket pair. A request carries the command's folder and
// arguments (JSON) and, as SCM_RIGHTS, the write ends of the two pipes the server reads the
// draft's stdout and stderr from; the worker answers each with the exit code. A cancel
// names the request it is for, so a late one never ends the next draft.
#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "serve/child.hpp"

namespace stipplot::serve {

// The argument that makes `stipplot` the draft worker (main.cpp), on the socket as its stdin.
inline constexpr const char* kDraftWorkerArg = "--studio-draft-worker";

// The worker's side: serves requests on the socket `fd` until the server closes it. In
// each forked child, `run` gets the command line (argv[0] the program's name) with stdout
// and stderr on the server's pipes, and returns the exit code. Returns 0 when the server
// has gone, 1 on a broken request.
int serve_drafts(int fd, const std::function<int(int argc, char** argv)>& run);

// The server's side: one worker, started on first use, one draft at a time.
class DraftWorker {
 public:
  // start_argv: the worker's command line ({executable, kDraftWorkerArg}).
  explicit DraftWorker(std::vector<std::string> start_argv);
  ~DraftWorker();
  DraftWorker(const DraftWorker&) = delete;
  DraftWorker& operator=(const DraftWorker&) = delete;

  // One draft: cancelled (from any thread) with cancel().
  struct Job {
    std::atomic<bool> cancelled{false};
    uint64_t id = 0;
  };
  // Runs args (args[0] the program's name, as a child's argv) in folder cwd and reads it to
  // its end; r.cancelled when cancel() ended it. Throws std::runtime_error when the worker
  // cannot start or has died (the next call starts another): the caller then starts the
  // command as a process of its own. O(output).
  ChildResult run(const std::vector<std::string>& args, const std::string& cwd, Job& job);
  // Ends the job: before it starts, or while it runs.
  void cancel(Job& job);
  // The worker's process (-1 before the first draft): for tests.
  pid_t worker_pid();

 private:
  void start();  // with run_mutex_ held
  void stop();   // with run_mutex_ held: closes the link, reaps the worker
  std::vector<std::string> start_argv_;
  std::mutex run_mutex_;   // one draft at a time
  std::mutex link_mutex_;  // guards the fields below and sends on the socket
  int fd_ = -1;
  pid_t pid_ = -1;
  uint64_t next_id_ = 1;
  Job* running_ = nullptr;
};

}  // namespace stipplot::serve
