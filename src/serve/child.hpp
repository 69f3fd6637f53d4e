#pragma once
// The studio runs its drawings and plots as `stipplot` child processes with the very
// command lines it shows the user: what the page previews, downloads and plots is what
// the CLI does, and stale work is cancelled by ending its process.
#include <sys/types.h>

#include <atomic>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace stipplot::serve {

struct ChildResult {
  int exit_code = -1;      // -1 when ended by a signal
  bool cancelled = false;  // ended by cancel()
  std::string out, err;
};

// One child process: started, read to its end, cancellable from another thread.
class Child {
 public:
  Child() = default;
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child();

  // Starts argv[0] with argv (no shell) in folder `cwd` (empty: this one). Throws
  // std::runtime_error when it cannot.
  void start(const std::vector<std::string>& argv, const std::string& cwd = "");
  // Writes a line to the child's standard input (false once it has gone).
  bool send_line(const std::string& line);
  // Reads stdout and stderr until the child exits; each complete stderr line is handed
  // to `on_err_line` as it arrives. O(output).
  ChildResult wait(const std::function<void(const std::string&)>& on_err_line = {});
  // Ends the child (SIGKILL); wait() then reports cancelled.
  void cancel();
  pid_t pid() const { return pid_.load(); }

 private:
  std::atomic<pid_t> pid_{-1};
  std::atomic<bool> cancelled_{false};
  int in_fd_ = -1, out_fd_ = -1, err_fd_ = -1;
  std::mutex in_mutex_;
};

// A command line and the children's environment as execve takes them, made before fork:
// nothing may be allocated between fork and exec in a server with threads.
class ExecArgs {
 public:
  explicit ExecArgs(std::vector<std::string> argv);
  char* const* argv() const { return argv_.data(); }
  char* const* envp() const { return envp_.data(); }

 private:
  std::vector<std::string> args_, env_;
  std::vector<char*> argv_, envp_;
};

// Reads two pipes (a child's stdout and stderr) into r until both are closed; each
// complete stderr line also goes to on_err_line. O(output).
void read_outputs(int out_fd, int err_fd, ChildResult& r, const std::function<void(const std::string&)>& on_err_line = {});

// Runs argv to its end. O(output).
// A child's --json line (the last line it printed) as JSON; an empty object when it is not.
nlohmann::json last_json_line(const std::string& out);

ChildResult run_child(const std::vector<std::string>& argv, const std::string& cwd = "");

}  // namespace stipplot::serve
