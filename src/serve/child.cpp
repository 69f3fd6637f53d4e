#include "serve/child.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "util/executable.hpp"

extern char** environ;

namespace stipplot::serve {

ExecArgs::ExecArgs(std::vector<std::string> argv) : args_(std::move(argv)), env_(environment_on_huge_pages()) {
  for (auto& a : args_) argv_.push_back(a.data());
  argv_.push_back(nullptr);
  for (auto& e : env_) envp_.push_back(e.data());
  envp_.push_back(nullptr);
}

Child::~Child() {
  cancel();
  if (pid_.load() > 0) ::waitpid(pid_.load(), nullptr, 0);
  for (int fd : {in_fd_, out_fd_, err_fd_})
    if (fd >= 0) ::close(fd);
}

void Child::start(const std::vector<std::string>& argv, const std::string& cwd) {
  int in[2], out[2], err[2];
  if (::pipe2(in, O_CLOEXEC) != 0 || ::pipe2(out, O_CLOEXEC) != 0 || ::pipe2(err, O_CLOEXEC) != 0)
    throw std::runtime_error("cannot make pipes for a child process");
  const ExecArgs exec(argv);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("cannot start a child process");
  if (pid == 0) {
    // Only async-signal-safe calls between fork and exec: the server has threads.
    ::dup2(in[0], 0);
    ::dup2(out[1], 1);
    ::dup2(err[1], 2);
    if (!cwd.empty() && ::chdir(cwd.c_str()) != 0) ::_exit(127);
    ::execve(exec.argv()[0], exec.argv(), exec.envp());
    ::_exit(127);
  }
  ::close(in[0]);
  ::close(out[1]);
  ::close(err[1]);
  in_fd_ = in[1];
  out_fd_ = out[0];
  err_fd_ = err[0];
  pid_.store(pid);
  if (cancelled_.load()) ::kill(pid, SIGKILL);
}

bool Child::send_line(const std::string& line) {
  std::lock_guard<std::mutex> lock(in_mutex_);
  if (in_fd_ < 0) return false;
  const std::string s = line + "\n";
  return ::write(in_fd_, s.data(), s.size()) == static_cast<ssize_t>(s.size());
}

void Child::cancel() {
  cancelled_.store(true);
  const pid_t p = pid_.load();
  if (p > 0) ::kill(p, SIGKILL);
}

void read_outputs(int out_fd, int err_fd, ChildResult& r, const std::function<void(const std::string&)>& on_err_line) {
  std::string err_line;
  pollfd fds[2] = {{out_fd, POLLIN, 0}, {err_fd, POLLIN, 0}};
  int open = 2;
  char buf[65536];
  while (open > 0) {
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      const ssize_t n = ::read(fds[i].fd, buf, sizeof buf);
      if (n <= 0) {
        fds[i].fd = -1;
        --open;
        continue;
      }
      if (i == 0) {
        r.out.append(buf, static_cast<size_t>(n));
        continue;
      }
      r.err.append(buf, static_cast<size_t>(n));
      for (ssize_t k = 0; k < n; ++k) {
        if (buf[k] != '\n') {
          err_line += buf[k];
        } else {
          if (on_err_line) on_err_line(err_line);
          err_line.clear();
        }
      }
    }
  }
}

ChildResult Child::wait(const std::function<void(const std::string&)>& on_err_line) {
  ChildResult r;
  read_outputs(out_fd_, err_fd_, r, on_err_line);
  int status = 0;
  const pid_t p = pid_.exchange(-1);
  if (p > 0) ::waitpid(p, &status, 0);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.cancelled = cancelled_.load();
  {
    std::lock_guard<std::mutex> lock(in_mutex_);
    if (in_fd_ >= 0) ::close(in_fd_);
    in_fd_ = -1;
  }
  return r;
}

ChildResult run_child(const std::vector<std::string>& argv, const std::string& cwd) {
  Child c;
  c.start(argv, cwd);
  return c.wait();
}

nlohmann::json last_json_line(const std::string& out) {
  const size_t end = out.find_last_not_of('\n');
  if (end == std::string::npos) return nlohmann::json::object();
  const size_t start = out.rfind('\n', end);
  auto j = nlohmann::json::parse(out.substr(start == std::string::npos ? 0 : start + 1, end + 1), nullptr, false);
  return j.is_discarded() ? nlohmann::json::object() : j;
}

}  // namespace stipplot::serve
