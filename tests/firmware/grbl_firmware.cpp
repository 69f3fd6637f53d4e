#include "firmware/grbl_firmware.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace firmware {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::string tail_of(const std::string& text, size_t n) { return text.size() > n ? text.substr(text.size() - n) : text; }

bool realtime_byte(unsigned char c) { return c == '?' || c == '!' || c == '~' || c == 0x18 || c >= 0x80; }

struct Pty {
  int master = -1, slave = -1;
  std::string path;
};

// A pty pair in raw mode. Every descriptor is close-on-exec, so neither the firmware nor
// a stipplot process started by a test holds a master open: closing ours hangs up the
// client.
Pty open_pty() {
  Pty p;
  p.master = ::open("/dev/ptmx", O_RDWR | O_NOCTTY | O_CLOEXEC | O_NONBLOCK);
  if (p.master < 0) throw std::runtime_error(std::string("cannot open /dev/ptmx: ") + std::strerror(errno));
  char name[128];
  if (::grantpt(p.master) != 0 || ::unlockpt(p.master) != 0 || ::ptsname_r(p.master, name, sizeof name) != 0) {
    ::close(p.master);
    throw std::runtime_error(std::string("cannot set up a pty: ") + std::strerror(errno));
  }
  p.path = name;
  p.slave = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (p.slave < 0) {
    ::close(p.master);
    throw std::runtime_error("cannot open " + p.path + ": " + std::strerror(errno));
  }
  termios t{};
  ::tcgetattr(p.slave, &t);
  ::cfmakeraw(&t);
  ::tcsetattr(p.slave, TCSANOW, &t);
  return p;
}

// Starts grbl_avr on `tty` (stdin and stdout) with its messages in `err_fd`, in its own
// session so that terminal signals of the test do not reach it.
pid_t spawn_firmware(const std::vector<std::string>& args, int tty, int err_fd, const std::string& cwd) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const char* dir = cwd.c_str();
  pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {  // only async-signal-safe calls until exec
    ::setsid();
    ::dup2(tty, 0);
    ::dup2(tty, 1);
    ::dup2(err_fd, 2);
    if (::chdir(dir) != 0) ::_exit(126);
    ::syscall(SYS_close_range, 3u, ~0u, 0u);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

// Bytes waiting for one direction of the wire: held for `latency` (a USB-serial adapter's
// frame and buffer delay), then sent no faster than a UART at `rate` (0: as fast as the
// pty takes them; grbl_avr puts bytes on its simulated wire at 115200 baud itself).
struct Paced {
  std::string q;
  double rate = 0;  // bytes per second; 0 = as fast as the pty takes them
  Clock::duration latency{0};
  double credit = 0;
  Clock::time_point last = Clock::now();
  std::deque<std::pair<Clock::time_point, size_t>> held;  // (release time, end offset in q)
  size_t released = 0;
  void push(const char* p, size_t n) {
    q.append(p, n);
    if (latency.count() > 0) held.emplace_back(Clock::now() + latency, q.size());
    else released = q.size();
  }
  void push(const std::string& s) { push(s.data(), s.size()); }
  void clear() {
    q.clear();
    held.clear();
    released = 0;
  }
  size_t allowed() {
    auto now = Clock::now();
    while (!held.empty() && held.front().first <= now) {
      released = held.front().second;
      held.pop_front();
    }
    if (rate <= 0) return released;
    credit = std::min(16.0, credit + rate * std::chrono::duration<double>(now - last).count());  // a 16-byte FIFO
    last = now;
    return std::min(released, static_cast<size_t>(std::max(0.0, credit)));
  }
  void sent(size_t n) {
    q.erase(0, n);
    released -= n;
    for (auto& h : held) h.second -= n;
    credit -= rate > 0 ? static_cast<double>(n) : 0;
  }
};

struct SessionInfo {
  pid_t pid = -1;
  std::string dir, step_path, err_path, tty;
  bool power_cut = false, exited = false;
  std::vector<SessionEvent> events;
};

}  // namespace

std::string ensure_grbl_avr(const std::string& dir_in) {
  static std::mutex mu;
  static std::set<std::string> built;
  std::lock_guard<std::mutex> lk(mu);
  const std::string dir = dir_in.empty() ? std::string(STIPPLOT_GRBL_AVR_DIR) : dir_in;
  const std::string exe = dir + "/bin/grbl_avr";
  if (built.count(dir)) return exe;
  fs::create_directories(fs::path(dir).parent_path());
  int lock = ::open((dir + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock < 0) throw std::runtime_error("cannot create " + dir + ".lock");
  ::flock(lock, LOCK_EX);
  const std::string log = dir + ".log";
  const std::string cmd = "bash " + quoted(std::string(STIPPLOT_SHARED_DIR) + "/validators/grbl-avr/build.sh") + " " +
                          quoted(dir) + " >" + quoted(log) + " 2>&1";
  int rc = std::system(cmd.c_str());
  ::flock(lock, LOCK_UN);
  ::close(lock);
  if (rc != 0 || ::access(exe.c_str(), X_OK) != 0)
    throw std::runtime_error("building grbl-avr failed (" + cmd + "):\n" + tail_of(slurp(log), 2000));
  built.insert(dir);
  return exe;
}

std::string settings_file(const std::string& name) {
  if (name.find('/') != std::string::npos) return name;
  std::string p = std::string(STIPPLOT_SHARED_DIR) + "/validators/grbl/settings/" + name + ".nc";
  if (::access(p.c_str(), R_OK) != 0) throw std::runtime_error("no grbl settings file " + p);
  return p;
}

struct GrblFirmware::Impl {
  FirmwareOptions opt;
  std::string exe, dir, settings_path;
  bool own_dir = false;
  MachineSettings settings;
  Clock::time_point t0 = Clock::now();

  mutable std::mutex mu;
  std::condition_variable cv;
  std::thread relay;
  bool stop = false;
  int wake[2] = {-1, -1};
  unsigned gen = 0;  // bumped whenever a descriptor changes: events polled before are stale

  int a = -1;  // master of the firmware's pty
  int b = -1;  // master of the client's pty
  std::string b_path;
  bool b_open = false;  // the client has it open
  Paced to_a, to_b;
  std::string a_partial, b_partial;
  uint64_t a_written = 0;
  struct Pending {
    size_t line;
    uint64_t end;  // offset just past the line in the bytes written to the firmware
  };
  std::deque<Pending> pending;  // lines grbl has not answered yet, oldest first
  std::vector<size_t> flushed_at_reset;  // lines the last reset dropped, until grbl answers a line
  std::vector<HostLine> lines;
  std::vector<DeviceLine> device;
  std::vector<SessionInfo> sessions;
  int cur = -1;
  double t_last_reply = 0;

  bool trig_armed = false, trig_fired = false;
  size_t trig_n = 0, trig_seen = 0;
  Cut trig_how = Cut::DropLink;
  std::function<bool(const std::string&)> trig_counts;

  ~Impl();
  double now() const { return std::chrono::duration<double>(Clock::now() - t0).count(); }
  void poke() const {
    char c = 1;
    [[maybe_unused]] ssize_t w = ::write(wake[1], &c, 1);
  }
  void loop();
  void pump_firmware(short revents, size_t can_write);
  void pump_client(short revents, size_t can_write);
  void on_device(const char* p, size_t n);
  void device_line(const std::string& text, bool forwarded);
  void on_client(const char* p, size_t n);
  void lose_unwritten();
  void deliver_unwritten();
  void drop_link_locked();
  void power_cut_locked();
  void start_session(bool send_settings);
  void power_off_clean();
  std::string open_client();
  size_t send_locked(const std::string& line);
  template <class Pred>
  bool wait_for(std::unique_lock<std::mutex>& lk, double timeout_s, Pred p) {
    return cv.wait_for(lk, std::chrono::duration<double>(timeout_s), p);
  }
  // A client that has just exited: the relay notices the hang-up within a few ms.
  void wait_client_gone(std::unique_lock<std::mutex>& lk) {
    wait_for(lk, 1, [&] { return !(b >= 0 && b_open); });
  }
};

// ---- the relay thread ----

void GrblFirmware::Impl::loop() {
  std::unique_lock<std::mutex> lk(mu);
  while (!stop) {
    pollfd p[3];
    int n = 0, ia = -1, ib = -1;
    p[n++] = {wake[0], POLLIN, 0};
    const size_t can_a = a >= 0 ? to_a.allowed() : 0, can_b = b >= 0 && b_open ? to_b.allowed() : 0;
    if (a >= 0) {
      ia = n;
      p[n++] = {a, static_cast<short>(POLLIN | (can_a ? POLLOUT : 0)), 0};
    }
    if (b >= 0 && b_open) {
      ib = n;
      p[n++] = {b, static_cast<short>(POLLIN | (can_b ? POLLOUT : 0)), 0};
    }
    // A closed client pty polls as hung up all the time: look at it every 2 ms instead.
    int timeout = b >= 0 && !b_open ? 2 : 100;
    if ((a >= 0 && !to_a.q.empty() && !can_a) || (b >= 0 && b_open && !to_b.q.empty() && !can_b)) timeout = 1;  // paced
    const unsigned g = gen;
    lk.unlock();
    ::poll(p, static_cast<nfds_t>(n), timeout);
    lk.lock();
    if (p[0].revents & POLLIN) {
      char buf[64];
      while (::read(wake[0], buf, sizeof buf) > 0) {
      }
    }
    if (g != gen) continue;
    if (ia >= 0) pump_firmware(p[ia].revents, can_a);
    if (g != gen) continue;
    if (b >= 0 && !b_open) {
      pollfd q{b, POLLIN, 0};
      ::poll(&q, 1, 0);
      b_open = !(q.revents & POLLHUP);  // the client opened it
    } else if (ib >= 0) {
      pump_client(p[ib].revents, can_b);
    }
    cv.notify_all();
  }
}

void GrblFirmware::Impl::pump_firmware(short revents, size_t can_write) {
  if (revents & (POLLIN | POLLHUP | POLLERR)) {
    char buf[4096];
    for (;;) {
      ssize_t r = ::read(a, buf, sizeof buf);
      if (r > 0) {
        on_device(buf, static_cast<size_t>(r));
        continue;
      }
      if (r < 0 && (errno == EAGAIN || errno == EINTR)) break;
      ::close(a);  // the firmware exited or died
      a = -1;
      ++gen;
      if (cur >= 0) sessions[static_cast<size_t>(cur)].exited = true;
      return;
    }
  }
  can_write = std::min(can_write, to_a.q.size());
  if ((revents & POLLOUT) && can_write) {
    ssize_t w = ::write(a, to_a.q.data(), can_write);
    if (w > 0) {
      a_written += static_cast<uint64_t>(w);
      to_a.sent(static_cast<size_t>(w));
    }
  }
}

void GrblFirmware::Impl::pump_client(short revents, size_t can_write) {
  if (revents & (POLLIN | POLLHUP | POLLERR)) {
    char buf[4096];
    for (;;) {
      ssize_t r = ::read(b, buf, sizeof buf);
      if (r > 0) {
        on_client(buf, static_cast<size_t>(r));
        if (b < 0) return;  // a cut fired
        continue;
      }
      if (r < 0 && (errno == EAGAIN || errno == EINTR)) break;
      b_open = false;  // the client closed the port (EIO): it may open it again
      to_b.clear();
      return;
    }
  }
  can_write = std::min(can_write, to_b.q.size());
  if ((revents & POLLOUT) && can_write) {
    ssize_t w = ::write(b, to_b.q.data(), can_write);
    if (w > 0) to_b.sent(static_cast<size_t>(w));
  }
}

void GrblFirmware::Impl::on_device(const char* p, size_t n) {
  const bool forward = b >= 0 && b_open;
  if (forward) to_b.push(p, n);
  for (size_t i = 0; i < n; ++i) {
    if (p[i] == '\n') {
      if (!a_partial.empty() && a_partial.back() == '\r') a_partial.pop_back();
      device_line(a_partial, forward);
      a_partial.clear();
    } else {
      a_partial += p[i];
    }
  }
}

void GrblFirmware::Impl::device_line(const std::string& text, bool forwarded) {
  device.push_back({text, cur, now(), forwarded});
  SessionInfo& s = sessions[static_cast<size_t>(cur)];
  const bool ok = text == "ok", err = text.rfind("error:", 0) == 0;
  if ((ok || err) && !pending.empty()) {
    HostLine& h = lines[pending.front().line];
    pending.pop_front();
    h.reply = ok ? HostLine::Reply::Ok : HostLine::Reply::Error;
    h.error = err ? std::atoi(text.c_str() + 6) : 0;
    h.t_reply = now();
    h.reply_forwarded = forwarded;
    t_last_reply = h.t_reply;
    s.events.push_back({SessionEvent::Kind::Line, static_cast<size_t>(&h - lines.data())});
    flushed_at_reset.clear();
  } else if ((ok || err) && !flushed_at_reset.empty()) {
    // A reply to no line the relay saw start: grbl was reset while lines were on the wire
    // (up to 127 bytes with character counting) and ran what arrived after the reset: the
    // tail of the line it was receiving, then the whole lines behind it (seen on the AVR
    // binary). Which ones, the record reads from the step log.
    HostLine h;
    h.session = cur;
    h.fragment_of = flushed_at_reset;
    h.reply = ok ? HostLine::Reply::Ok : HostLine::Reply::Error;
    h.error = err ? std::atoi(text.c_str() + 6) : 0;
    h.t_sent = h.t_reply = now();
    h.reply_forwarded = forwarded;
    lines.push_back(h);
    s.events.push_back({SessionEvent::Kind::Line, lines.size() - 1});
  } else if (text.rfind("Grbl ", 0) == 0) {  // boot or reset: grbl's buffers were emptied
    flushed_at_reset.clear();
    for (const Pending& q : pending) {
      lines[q.line].reply = HostLine::Reply::Flushed;
      flushed_at_reset.push_back(q.line);
    }
    pending.clear();
    s.events.push_back({SessionEvent::Kind::Reset, 0, device.size() - 1});
  }
}

void GrblFirmware::Impl::on_client(const char* p, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    const char c = p[i];
    to_a.push(&c, 1);
    if (realtime_byte(static_cast<unsigned char>(c))) continue;  // grbl's serial ISR takes these
    if (c != '\n' && c != '\r') {
      b_partial += c;
      continue;
    }
    HostLine h;
    h.text = b_partial;
    h.session = cur;
    h.t_sent = now();
    lines.push_back(h);
    pending.push_back({lines.size() - 1, a_written + to_a.q.size()});
    b_partial.clear();
    if (trig_armed && (!trig_counts || trig_counts(lines.back().text)) && ++trig_seen == trig_n) {
      trig_armed = false;
      trig_fired = true;
      deliver_unwritten();
      if (trig_how == Cut::DropLink) {
        drop_link_locked();
      } else {
        // Let the line cross grbl_avr's simulated wire (87 us a byte) before the power goes.
        std::this_thread::sleep_for(std::chrono::milliseconds(15));
        power_cut_locked();
      }
      return;  // the rest of the client's bytes were on the wire when it was cut
    }
  }
}

// A triggered cut comes right after the line that fired it reached grbl: write what the
// relay still holds (up to that line's end) and wait until grbl_avr has read it from its
// pty, at most 0.5 s. (grbl_avr then puts it on its simulated wire, 86.8 us a byte.)
void GrblFirmware::Impl::deliver_unwritten() {
  if (a < 0 || cur < 0) return;
  auto end = Clock::now() + std::chrono::milliseconds(500);
  while (!to_a.q.empty() && Clock::now() < end) {
    to_a.released = to_a.q.size();
    to_a.held.clear();
    ssize_t w = ::write(a, to_a.q.data(), to_a.q.size());
    if (w > 0) {
      a_written += static_cast<uint64_t>(w);
      to_a.sent(static_cast<size_t>(w));
    } else {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }
  int tty = ::open(sessions[static_cast<size_t>(cur)].tty.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (tty < 0) return;
  int queued = 1;
  while (::ioctl(tty, FIONREAD, &queued) == 0 && queued > 0 && Clock::now() < end)
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  ::close(tty);
}

// Bytes still in the relay never reached the firmware: their lines were not received.
void GrblFirmware::Impl::lose_unwritten() {
  to_a.clear();
  while (!pending.empty() && pending.back().end > a_written) pending.pop_back();
}

void GrblFirmware::Impl::drop_link_locked() {
  if (b >= 0) ::close(b);
  b = -1;
  b_open = false;
  b_path.clear();
  to_b.clear();
  b_partial.clear();
  lose_unwritten();
  ++gen;
  poke();
}

// The board loses power: grbl_avr is frozen at once (SIGSTOP), the client hangs up, what
// grbl had already written is read, then grbl_avr is told to stop (SIGTERM): it ends
// within 1 ms of simulated time and writes its step log whole. Bytes it writes after the
// freeze never reach anybody.
void GrblFirmware::Impl::power_cut_locked() {
  if (cur < 0) return;
  SessionInfo& s = sessions[static_cast<size_t>(cur)];
  if (s.pid > 0) ::kill(s.pid, SIGSTOP);
  drop_link_locked();
  if (a >= 0) {  // replies the firmware wrote before it froze
    char buf[4096];
    ssize_t r;
    while ((r = ::read(a, buf, sizeof buf)) > 0) on_device(buf, static_cast<size_t>(r));
  }
  if (s.pid > 0) {
    ::kill(s.pid, SIGTERM);
    ::kill(s.pid, SIGCONT);
    ::waitpid(s.pid, nullptr, 0);
  }
  s.pid = -1;
  s.power_cut = true;
  if (a >= 0) ::close(a);
  a = -1;
  a_partial.clear();
  pending.clear();
  to_a.clear();
  ++gen;
  poke();
}

// ---- sessions and the client pty (called from the test's thread) ----

size_t GrblFirmware::Impl::send_locked(const std::string& line) {
  if (a < 0) throw std::runtime_error("the firmware is not running (power cut?)");
  if (b >= 0 && b_open) throw std::runtime_error("a client has the port open: the harness cannot talk to grbl now");
  HostLine h;
  h.text = line;
  h.session = cur;
  h.from_client = false;
  h.t_sent = now();
  lines.push_back(h);
  to_a.push(line + "\n");
  pending.push_back({lines.size() - 1, a_written + to_a.q.size()});
  poke();
  return lines.size() - 1;
}

void GrblFirmware::Impl::start_session(bool send_settings) {
  SessionInfo s;
  const size_t idx = sessions.size();
  s.dir = dir + "/session-" + std::to_string(idx);
  fs::create_directories(s.dir);
  s.step_path = s.dir + "/steps.txt";
  s.err_path = s.dir + "/stderr.txt";
  Pty pa = open_pty();
  int err_fd = ::open(s.err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (err_fd < 0) throw std::runtime_error("cannot create " + s.err_path);
  char t[32];
  std::snprintf(t, sizeof t, "%g", opt.timescale);
  // The EEPROM image lives in the work dir, so settings survive a power cut as on the board.
  s.pid = spawn_firmware({exe, "-t", t, "-s", s.step_path, "-e", dir + "/eeprom.bin"}, pa.slave, err_fd, dir);
  s.tty = pa.path;
  ::close(pa.slave);
  ::close(err_fd);
  {
    std::unique_lock<std::mutex> lk(mu);
    sessions.push_back(s);
    cur = static_cast<int>(idx);
    a = pa.master;
    a_partial.clear();
    to_a.clear();
    ++gen;
    poke();
    auto booted = [&] {
      for (size_t i = device.size(); i-- > 0 && device[i].session == cur;)
        if (device[i].text.rfind("Grbl ", 0) == 0) return true;
      return false;
    };
    if (!wait_for(lk, 20, booted))
      throw std::runtime_error("grbl_avr printed no banner within 20 s (" + exe + ", log " + s.dir + ")");
  }
  if (settings_path.empty() || !send_settings) return;
  std::istringstream in(slurp(settings_path));
  std::string line;
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.empty()) continue;
    std::unique_lock<std::mutex> lk(mu);
    size_t i = send_locked(line);
    const bool answered = wait_for(lk, 10, [&] { return lines[i].reply != HostLine::Reply::None; });
    if (!answered || lines[i].reply != HostLine::Reply::Ok) {
      std::string said;
      for (size_t k = device.size() > 8 ? device.size() - 8 : 0; k < device.size(); ++k) said += " | " + device[k].text;
      throw std::runtime_error("grbl " + std::string(!answered ? "did not answer" : lines[i].reply == HostLine::Reply::Flushed ? "reset before answering" : "refused") +
                               " setting `" + line + "` from " + settings_path + " (error:" + std::to_string(lines[i].error) +
                               "); it last said" + said);
    }
  }
}

// Ctrl-F: grbl_avr stops once grbl is idle, writing its EEPROM image and step log.
void GrblFirmware::Impl::power_off_clean() {
  std::unique_lock<std::mutex> lk(mu);
  if (b >= 0) drop_link_locked();
  if (a < 0 || cur < 0) return;
  SessionInfo& s = sessions[static_cast<size_t>(cur)];
  to_a.push("\x06");
  poke();
  if (!wait_for(lk, 20, [&] { return a < 0; })) throw std::runtime_error("grbl_avr did not exit after Ctrl-F");
  if (s.pid > 0) ::waitpid(s.pid, nullptr, 0);
  s.pid = -1;
}

std::string GrblFirmware::Impl::open_client() {
  Pty pb = open_pty();
  ::close(pb.slave);  // hung up until the client opens it
  std::lock_guard<std::mutex> lk(mu);
  b = pb.master;
  b_path = pb.path;
  b_open = false;
  ++gen;
  poke();
  return b_path;
}

// ---- GrblFirmware ----

GrblFirmware::GrblFirmware(FirmwareOptions o) : impl_(std::make_unique<Impl>()) {
  Impl& I = *impl_;
  I.opt = o;
  I.exe = ensure_grbl_avr();
  if (!o.settings.empty()) {
    I.settings_path = settings_file(o.settings);
    I.settings = MachineSettings::load(I.settings_path);
  }
  if (o.dir.empty()) {
    static std::atomic<int> counter{0};
    I.dir = (fs::temp_directory_path() / ("stipplot-grbl-" + std::to_string(::getpid()) + "-" + std::to_string(counter++))).string();
    I.own_dir = true;
  } else {
    I.dir = o.dir;
  }
  fs::create_directories(I.dir);
  if (::pipe2(I.wake, O_CLOEXEC | O_NONBLOCK) != 0) throw std::runtime_error("pipe2 failed");
  I.to_a.rate = I.to_b.rate = o.baud / 10.0;  // 8N1: 10 bits a byte
  I.to_a.latency = I.to_b.latency = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(o.latency_ms));
  I.relay = std::thread([&I] { I.loop(); });
  // A throw from here on destroys impl_, whose destructor stops the relay and the firmware.
  I.start_session(true);
  if (o.power_cycle_after_settings) {
    I.power_off_clean();
    I.start_session(false);
  }
  I.open_client();
}

GrblFirmware::~GrblFirmware() = default;

GrblFirmware::Impl::~Impl() {
  Impl& I = *this;
  {
    std::lock_guard<std::mutex> lk(I.mu);
    I.stop = true;
    I.poke();
  }
  if (I.relay.joinable()) I.relay.join();
  // What the test needed of the logs it has read: the firmware is simply killed.
  for (SessionInfo& s : I.sessions) {
    if (s.pid <= 0) continue;
    ::kill(s.pid, SIGKILL);
    ::waitpid(s.pid, nullptr, 0);
    s.pid = -1;
  }
  for (int fd : {I.a, I.b, I.wake[0], I.wake[1]})
    if (fd >= 0) ::close(fd);
  if (I.own_dir && !std::getenv("STIPPLOT_KEEP_FIRMWARE_LOGS")) {
    std::error_code ec;
    fs::remove_all(I.dir, ec);
  }
}

std::string GrblFirmware::port() const {
  std::lock_guard<std::mutex> lk(impl_->mu);
  return impl_->b_path;
}

void GrblFirmware::drop_link() {
  std::lock_guard<std::mutex> lk(impl_->mu);
  impl_->drop_link_locked();
}

std::string GrblFirmware::reconnect() {
  {
    std::lock_guard<std::mutex> lk(impl_->mu);
    if (impl_->b >= 0) throw std::runtime_error("the link is up: drop it before reconnecting");
  }
  return impl_->open_client();
}

void GrblFirmware::power_cut() {
  std::lock_guard<std::mutex> lk(impl_->mu);
  impl_->power_cut_locked();
}

std::string GrblFirmware::power_on() {
  {
    std::lock_guard<std::mutex> lk(impl_->mu);
    if (impl_->a >= 0) throw std::runtime_error("the firmware is running: cut the power first");
    if (impl_->b >= 0) impl_->drop_link_locked();
  }
  impl_->start_session(true);
  return impl_->open_client();
}

std::string GrblFirmware::power_cycle() {
  impl_->power_off_clean();
  impl_->start_session(false);
  return impl_->open_client();
}

void GrblFirmware::cut_after_client_lines(size_t n, Cut how, std::function<bool(const std::string&)> counts) {
  std::lock_guard<std::mutex> lk(impl_->mu);
  Impl& I = *impl_;
  I.trig_armed = n > 0;
  I.trig_fired = false;
  I.trig_n = n;
  I.trig_seen = 0;
  I.trig_how = how;
  I.trig_counts = std::move(counts);
}

bool GrblFirmware::cut_done() const {
  std::lock_guard<std::mutex> lk(impl_->mu);
  return impl_->trig_fired;
}

std::vector<std::string> GrblFirmware::command(const std::string& line, double timeout_s) {
  Impl& I = *impl_;
  std::unique_lock<std::mutex> lk(I.mu);
  I.wait_client_gone(lk);
  const size_t from = I.device.size();
  const size_t i = I.send_locked(line);
  if (!I.wait_for(lk, timeout_s, [&] { return I.lines[i].reply != HostLine::Reply::None; }))
    throw std::runtime_error("grbl did not answer `" + line + "` within " + std::to_string(timeout_s) + " s");
  std::vector<std::string> out;
  for (size_t k = from; k < I.device.size(); ++k) {
    out.push_back(I.device[k].text);
    if (I.device[k].text == "ok" || I.device[k].text.rfind("error:", 0) == 0) break;
  }
  return out;
}

std::vector<std::string> GrblFirmware::stream(const std::vector<std::string>& lines, double timeout_s) {
  Impl& I = *impl_;
  std::unique_lock<std::mutex> lk(I.mu);
  I.wait_client_gone(lk);
  auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  std::vector<size_t> sent;
  std::vector<std::string> replies;
  size_t next = 0, done = 0, in_buffer = 0;
  while (done < lines.size()) {
    while (next < lines.size() && in_buffer + lines[next].size() + 1 <= 127) {
      sent.push_back(I.send_locked(lines[next]));
      in_buffer += lines[next++].size() + 1;
    }
    if (!I.cv.wait_until(lk, end, [&] { return I.lines[sent[done]].reply != HostLine::Reply::None; }))
      throw std::runtime_error("grbl did not answer `" + lines[done] + "` in time");
    const HostLine& h = I.lines[sent[done]];
    replies.push_back(h.reply == HostLine::Reply::Ok ? "ok" : "error:" + std::to_string(h.error));
    in_buffer -= lines[done++].size() + 1;
  }
  return replies;
}

std::string GrblFirmware::status(double timeout_s) {
  Impl& I = *impl_;
  std::unique_lock<std::mutex> lk(I.mu);
  I.wait_client_gone(lk);
  if (I.a < 0) throw std::runtime_error("the firmware is not running");
  if (I.b >= 0 && I.b_open) throw std::runtime_error("a client has the port open: the harness cannot talk to grbl now");
  const size_t from = I.device.size();
  I.to_a.push("?");
  I.poke();
  std::string got;
  auto answered = [&] {
    for (size_t k = from; k < I.device.size(); ++k)
      if (!I.device[k].text.empty() && I.device[k].text[0] == '<') {
        got = I.device[k].text;
        return true;
      }
    return false;
  };
  if (!I.wait_for(lk, timeout_s, answered)) throw std::runtime_error("grbl sent no status report");
  return got;
}

void GrblFirmware::inject(const std::string& bytes) {
  Impl& I = *impl_;
  std::lock_guard<std::mutex> lk(I.mu);
  if (I.a < 0) throw std::runtime_error("the firmware is not running");
  I.to_a.push(bytes);
  I.poke();
}

void GrblFirmware::reset() {
  Impl& I = *impl_;
  std::unique_lock<std::mutex> lk(I.mu);
  if (I.a < 0) throw std::runtime_error("the firmware is not running");
  const size_t from = I.device.size();
  I.to_a.push("\x18");
  I.poke();
  auto booted = [&] {
    for (size_t k = from; k < I.device.size(); ++k)
      if (I.device[k].text.rfind("Grbl ", 0) == 0) return true;
    return false;
  };
  if (!I.wait_for(lk, 10, booted)) throw std::runtime_error("grbl did not restart after Ctrl-X");
}

bool GrblFirmware::wait_idle(double timeout_s) {
  auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (Clock::now() < end) {
    std::string s = status();
    bool unanswered;
    double quiet;
    {
      std::lock_guard<std::mutex> lk(impl_->mu);
      unanswered = !impl_->pending.empty();
      quiet = impl_->now() - impl_->t_last_reply;
    }
    // Idle with no line left unanswered (grbl also reports Idle during a dwell), or with
    // none answered for 2 s (lines that lost their end in an RX overflow never will be).
    if (s.rfind("<Idle", 0) == 0 && (!unanswered || quiet > 2)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

std::vector<HostLine> GrblFirmware::host_lines() const {
  std::lock_guard<std::mutex> lk(impl_->mu);
  return impl_->lines;
}

std::vector<DeviceLine> GrblFirmware::device_lines() const {
  std::lock_guard<std::mutex> lk(impl_->mu);
  return impl_->device;
}

MachineSettings GrblFirmware::settings() const { return impl_->settings; }
const std::string& GrblFirmware::dir() const { return impl_->dir; }

pid_t GrblFirmware::pid() const {
  std::lock_guard<std::mutex> lk(impl_->mu);
  return impl_->cur >= 0 ? impl_->sessions[static_cast<size_t>(impl_->cur)].pid : -1;
}

FirmwareRecord GrblFirmware::record() {
  const Impl& I = *impl_;
  std::string step_path;
  {
    std::lock_guard<std::mutex> lk(I.mu);
    if (I.cur >= 0 && I.sessions[static_cast<size_t>(I.cur)].pid > 0) step_path = I.sessions[static_cast<size_t>(I.cur)].step_path;
  }
  // grbl_avr buffers its step log and writes it out once a second of wall time (and whole
  // at exit): wait until the log's last step is where grbl says the machine stands (or,
  // while a client holds the port and grbl cannot be asked, for one write-out).
  if (!step_path.empty()) {
    Steps at;
    bool asked = false;
    try {
      asked = status_position(status(), I.settings, at);
    } catch (const std::runtime_error&) {
    }
    const auto end = Clock::now() + std::chrono::seconds(asked ? 10 : 0);
    do {
      const StepLog log = parse_step_log(slurp(step_path));
      if (asked && (log.steps.empty() ? at == Steps{} : log.steps.back().pos == at)) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(asked ? 100 : 1150));
    } while (Clock::now() < end);
  }
  FirmwareRecord r;
  std::vector<SessionInfo> sessions;
  {
    std::lock_guard<std::mutex> lk(I.mu);
    r.lines = I.lines;
    r.device = I.device;
    sessions = I.sessions;
  }
  r.settings = I.settings;
  for (size_t i = 0; i < sessions.size(); ++i) {
    const SessionInfo& s = sessions[i];
    SessionRecord sr = build_session(parse_step_log(slurp(s.step_path)), r.lines, s.events, I.settings, r.device);
    sr.index = static_cast<int>(i);
    sr.power_cut = s.power_cut;
    // simavr's UART holds 64 bytes; a host that overfills grbl's 128-byte RX buffer loses
    // bytes there, and simavr says so.
    const std::string err = slurp(s.err_path);
    for (size_t at = err.find("RX buffer overrun"); at != std::string::npos; at = err.find("RX buffer overrun", at + 1))
      ++sr.rx_overruns;
    r.sessions.push_back(std::move(sr));
  }
  return r;
}

}  // namespace firmware
