#include "serve/draft_worker.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace stipplot::serve {

namespace {

using nlohmann::json;

// A request carries at most this much JSON: a command line is a few hundred bytes.
constexpr size_t kMaxMessage = 1 << 18;

// One message on the socket: its text and the descriptors it carried.
struct Message {
  std::string text;
  std::vector<int> fds;
  bool closed = false;  // the other side has gone
};

void close_all(std::vector<int>& fds) {
  for (int fd : fds) ::close(fd);
  fds.clear();
}

// Sends text with fds attached; false when the other side has gone.
bool send_message(int sock, const std::string& text, const std::vector<int>& fds = {}) {
  iovec iov{const_cast<char*>(text.data()), text.size()};
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  std::vector<char> control;
  if (!fds.empty()) {
    control.assign(CMSG_SPACE(sizeof(int) * fds.size()), 0);
    msg.msg_control = control.data();
    msg.msg_controllen = control.size();
    cmsghdr* c = CMSG_FIRSTHDR(&msg);
    c->cmsg_level = SOL_SOCKET;
    c->cmsg_type = SCM_RIGHTS;
    c->cmsg_len = CMSG_LEN(sizeof(int) * fds.size());
    std::memcpy(CMSG_DATA(c), fds.data(), sizeof(int) * fds.size());
  }
  for (;;) {
    const ssize_t n = ::sendmsg(sock, &msg, MSG_NOSIGNAL);
    if (n >= 0) return static_cast<size_t>(n) == text.size();
    if (errno != EINTR) return false;
  }
}

Message receive_message(int sock) {
  Message m;
  std::vector<char> buf(kMaxMessage);
  iovec iov{buf.data(), buf.size()};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int) * 4)];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  ssize_t n;
  do n = ::recvmsg(sock, &msg, MSG_CMSG_CLOEXEC);
  while (n < 0 && errno == EINTR);
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); n >= 0 && c; c = CMSG_NXTHDR(&msg, c))
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_RIGHTS) {
      const size_t count = (c->cmsg_len - CMSG_LEN(0)) / sizeof(int);
      m.fds.resize(count);
      std::memcpy(m.fds.data(), CMSG_DATA(c), count * sizeof(int));
    }
  if (n <= 0 || (msg.msg_flags & (MSG_TRUNC | MSG_CTRUNC))) {
    close_all(m.fds);
    m.closed = true;
    return m;
  }
  m.text.assign(buf.data(), static_cast<size_t>(n));
  return m;
}

int exit_code_of(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : -1; }

// In the forked child: the command on the server's pipes, then out without the
// destructors of the worker's own state.
[[noreturn]] void run_draft(int sock, std::vector<int>& pipes, const json& req,
                            const std::function<int(int, char**)>& run) {
  ::close(sock);
  ::dup2(pipes[0], 1);
  ::dup2(pipes[1], 2);
  close_all(pipes);
  const int nul = ::open("/dev/null", O_RDONLY);
  if (nul >= 0) {
    ::dup2(nul, 0);
    ::close(nul);
  }
  ::signal(SIGPIPE, SIG_DFL);
  const std::string cwd = req.value("cwd", "");
  if (!cwd.empty() && ::chdir(cwd.c_str()) != 0) {
    std::fprintf(stderr, "stipplot: error: cannot enter the folder %s\n", cwd.c_str());
    ::_exit(1);
  }
  int code = 70;
  try {  // a request's arguments that are not strings end here too, not in std::terminate
    std::vector<std::string> args = req.at("args").get<std::vector<std::string>>();
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    code = run(static_cast<int>(args.size()), argv.data());
  } catch (...) {
    std::fprintf(stderr, "stipplot: internal error: the draft failed\n");
  }
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  ::_exit(code);
}

// Waits for the child while listening for a cancel; false when the server has gone.
bool watch(int sock, pid_t child, uint64_t id, int& status) {
  const int pidfd = static_cast<int>(::syscall(SYS_pidfd_open, child, 0));
  bool server = true;
  for (;;) {
    pollfd fds[2] = {{sock, POLLIN, 0}, {pidfd, POLLIN, 0}};
    // Without pidfd (kernels before 5.3) the child is looked at every 2 ms.
    const int ready = ::poll(fds, pidfd >= 0 ? 2 : 1, pidfd >= 0 ? -1 : 2);
    if (ready < 0 && errno != EINTR) break;
    if (::waitpid(child, &status, WNOHANG) == child) {
      if (pidfd >= 0) ::close(pidfd);
      return server;
    }
    if (ready > 0 && server && (fds[0].revents & (POLLIN | POLLHUP | POLLERR))) {
      Message m = receive_message(sock);
      close_all(m.fds);
      const json j = m.closed ? json() : json::parse(m.text, nullptr, false);
      if (m.closed) server = false;
      if (m.closed || (j.is_object() && j.value("cancel", uint64_t{0}) == id)) ::kill(child, SIGKILL);
    }
  }
  ::kill(child, SIGKILL);
  ::waitpid(child, &status, 0);
  if (pidfd >= 0) ::close(pidfd);
  return server;
}

}  // namespace

int serve_drafts(int sock, const std::function<int(int, char**)>& run) {
  // The heap as main() sets it up: large blocks kept for the next draft, grown 64 MB at a time.
  for (;;) {
    Message m = receive_message(sock);
    if (m.closed) return 0;
    const json req = json::parse(m.text, nullptr, false);
    if (req.is_object() && req.contains("cancel")) {  // for a draft already ended
      close_all(m.fds);
      continue;
    }
    if (!req.is_object() || !req.contains("args") || !req["args"].is_array() || m.fds.size() != 2) {
      close_all(m.fds);
      return 1;
    }
    const uint64_t id = req.value("id", uint64_t{0});
    const pid_t child = ::fork();
    if (child == 0) run_draft(sock, m.fds, req, run);
    close_all(m.fds);  // the child holds the pipes: the server sees them close when it ends
    int status = 0;
    bool server = true;
    if (child > 0) server = watch(sock, child, id, status);
    const int code = child > 0 ? exit_code_of(status) : -1;
    if (!server || !send_message(sock, json{{"id", id}, {"exit", code}}.dump())) return 0;
  }
}

DraftWorker::DraftWorker(std::vector<std::string> start_argv) : start_argv_(std::move(start_argv)) {}

DraftWorker::~DraftWorker() {
  std::lock_guard<std::mutex> lock(run_mutex_);
  stop();
}

void DraftWorker::start() {
  int sv[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) != 0)
    throw std::runtime_error("cannot make the draft worker's socket");
  const ExecArgs exec(start_argv_);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(sv[0]);
    ::close(sv[1]);
    throw std::runtime_error("cannot start the draft worker");
  }
  if (pid == 0) {
    // Only async-signal-safe calls between fork and exec: the server has threads.
    ::dup2(sv[1], 0);
    const int nul = ::open("/dev/null", O_WRONLY);
    if (nul >= 0) ::dup2(nul, 1);
    ::execve(exec.argv()[0], exec.argv(), exec.envp());
    ::_exit(127);
  }
  ::close(sv[1]);
  std::lock_guard<std::mutex> lock(link_mutex_);
  fd_ = sv[0];
  pid_ = pid;
}

void DraftWorker::stop() {
  int fd;
  pid_t pid;
  {
    std::lock_guard<std::mutex> lock(link_mutex_);
    fd = fd_, pid = pid_;
    fd_ = -1, pid_ = -1;
    running_ = nullptr;
  }
  if (fd >= 0) ::close(fd);  // the worker ends its draft and itself
  if (pid > 0) ::waitpid(pid, nullptr, 0);
}

ChildResult DraftWorker::run(const std::vector<std::string>& args, const std::string& cwd, Job& job) {
  std::lock_guard<std::mutex> lock(run_mutex_);
  ChildResult r;
  if (job.cancelled.load()) {
    r.cancelled = true;
    return r;
  }
  int out[2], err[2];
  if (::pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error("cannot make pipes for a draft");
  if (::pipe2(err, O_CLOEXEC) != 0) {
    ::close(out[0]);
    ::close(out[1]);
    throw std::runtime_error("cannot make pipes for a draft");
  }
  bool sent = false;
  // A worker that has died since the last draft is started again, once.
  for (int attempt = 0; attempt < 2 && !sent; ++attempt) {
    if (fd_ < 0) start();
    {
      std::lock_guard<std::mutex> link(link_mutex_);
      job.id = next_id_++;
      running_ = &job;
      sent = send_message(fd_, json{{"id", job.id}, {"cwd", cwd}, {"args", args}}.dump(), {out[1], err[1]});
      if (!sent) running_ = nullptr;
    }
    if (!sent) stop();
  }
  ::close(out[1]);
  ::close(err[1]);
  if (!sent) {
    ::close(out[0]);
    ::close(err[0]);
    throw std::runtime_error("the draft worker does not answer");
  }
  // A cancel that came in before the job was running: now it is, so send it.
  if (job.cancelled.load()) cancel(job);
  read_outputs(out[0], err[0], r);
  ::close(out[0]);
  ::close(err[0]);
  const Message reply = receive_message(fd_);
  {
    std::lock_guard<std::mutex> link(link_mutex_);
    running_ = nullptr;
  }
  const json j = reply.closed ? json() : json::parse(reply.text, nullptr, false);
  if (!j.is_object() || j.value("id", uint64_t{0}) != job.id) {
    stop();
    throw std::runtime_error("the draft worker ended");
  }
  r.exit_code = j.value("exit", -1);
  r.cancelled = job.cancelled.load();
  return r;
}

pid_t DraftWorker::worker_pid() {
  std::lock_guard<std::mutex> link(link_mutex_);
  return pid_;
}

void DraftWorker::cancel(Job& job) {
  job.cancelled.store(true);
  std::lock_guard<std::mutex> link(link_mutex_);
  if (running_ == &job && fd_ >= 0) send_message(fd_, json{{"cancel", job.id}}.dump());
}

}  // namespace stipplot::serve
