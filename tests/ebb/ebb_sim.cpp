#include "ebb/ebb_sim.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "svg/svg_document.hpp"

namespace ebbtest {

namespace fs = std::filesystem;

namespace {
std::string slurp(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

double seg_dist(Pt p, Pt a, Pt b) {
  const double dx = b.x - a.x, dy = b.y - a.y, L2 = dx * dx + dy * dy;
  double t = L2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / L2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - a.x - t * dx, p.y - a.y - t * dy);
}

double path_dist(Pt p, const Path& path) {
  if (path.size() == 1) return std::hypot(p.x - path[0].x, p.y - path[0].y);
  double d = 1e18;
  for (size_t i = 1; i < path.size(); ++i) d = std::min(d, seg_dist(p, path[i - 1], path[i]));
  return d;
}
}  // namespace

std::string ensure_ebb_sim() {
  static std::mutex mu;
  static bool built = false;
  std::lock_guard<std::mutex> lk(mu);
  const std::string dir = STIPPLOT_EBB_SIM_DIR, exe = dir + "/bin/ebb_sim";
  if (built) return exe;
  fs::create_directories(fs::path(dir).parent_path());
  const int lock = ::open((dir + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock < 0) throw std::runtime_error("cannot create " + dir + ".lock");
  ::flock(lock, LOCK_EX);
  int rc = 0;
  const std::string log = dir + ".log";
  const std::string cmd = "sh '" + std::string(STIPPLOT_SHARED_DIR) + "/validators/ebb/build.sh' '" + dir + "' >'" + log + "' 2>&1";
  // Another test process may have built it meanwhile: build.sh re-extracts, so skip it then.
  if (::access(exe.c_str(), X_OK) != 0) rc = std::system(cmd.c_str());
  ::flock(lock, LOCK_UN);
  ::close(lock);
  if (rc != 0 || ::access(exe.c_str(), X_OK) != 0) {
    const std::string l = slurp(log);
    throw std::runtime_error("building ebb_sim failed (" + cmd + "):\n" + l.substr(l.size() > 2000 ? l.size() - 2000 : 0));
  }
  built = true;
  return exe;
}

SimLog read_log(const std::string& path, double spm) {
  SimLog out;
  std::ifstream in(path);
  std::string line;
  bool down = false;
  double down_since = 0;
  auto here = [&] { return Pt{static_cast<double>(out.m1 + out.m2) / (2 * spm), static_cast<double>(out.m1 - out.m2) / (2 * spm)}; };
  Path cur;
  while (std::getline(in, line)) {
    double t = 0;
    char kind[16] = {0};
    if (std::sscanf(line.c_str(), "%lf %15s", &t, kind) != 2) continue;
    const std::string k = kind;
    if (k == "STEP") {
      int motor = 0, dir = 0;
      long long pos = 0;
      if (std::sscanf(line.c_str(), "%*f STEP %d %d %lld", &motor, &dir, &pos) != 3) continue;
      (motor == 1 ? out.m1 : out.m2) = pos;
      ++out.steps;
      if (down) ++out.down_steps;
      if (out.first_step_s < 0) out.first_step_s = t;
      out.last_step_s = t;
      if (down) cur.push_back(here());
    } else if (k == "POS") {
      int motor = 0;
      long long pos = 0;
      if (std::sscanf(line.c_str(), "%*f POS %d %lld", &motor, &pos) == 2) (motor == 1 ? out.m1 : out.m2) = pos;
    } else if (k == "PEN") {
      const bool d = line.find("PEN DOWN") != std::string::npos;
      if (d && !down) {
        cur = {here()};
        down_since = t;
      } else if (!d && down && t - down_since >= 0.001) {
        // (The pin set-up at power-on flips the pen for 80 µs: not a mark.)
        out.marks.push_back(cur);
      }
      down = d;
    } else if (k == "START" || k == "RESET") {
      if (down && cur.size() > 1) out.marks.push_back(cur);  // drawn up to the reset
      down = false;
      out.m1 = out.m2 = 0;
    }
  }
  return out;
}

std::string run_job_file(const std::string& job_path, const std::string& log) {
  const std::string exe = ensure_ebb_sim();
  std::string input;
  std::istringstream job(slurp(job_path));
  std::string l;
  while (std::getline(job, l))
    if (!l.empty() && l[0] != '#') input += l + "\r";
  const std::string in_path = log + ".in", out_path = log + ".out";
  std::ofstream(in_path, std::ios::binary) << input;
  const std::string cmd = "'" + exe + "' -l '" + log + "' <'" + in_path + "' >'" + out_path + "'";
  if (std::system(cmd.c_str()) != 0) throw std::runtime_error("ebb_sim failed: " + cmd);
  return slurp(out_path);
}

namespace {
// A move's motor steps: an SM's or an LM's (LM,<r1>,<s1>,<a1>,<r2>,<s2>,<a2>[,clear]).
bool move_steps(const std::string& l, long long& s1, long long& s2) {
  long long a = 0, r = 0, c = 0, d = 0;
  if (std::sscanf(l.c_str(), "SM,%lld,%lld,%lld", &a, &s1, &s2) == 3) return true;
  return std::sscanf(l.c_str(), "LM,%lld,%lld,%lld,%lld,%lld,%lld", &r, &s1, &a, &c, &s2, &d) == 6;
}
}  // namespace

std::vector<Path> job_marks(const std::string& job_path, double spm) {
  std::vector<Path> out;
  std::istringstream job(slurp(job_path));
  std::string l;
  long long m1 = 0, m2 = 0;
  bool down = false;
  auto here = [&] { return Pt{static_cast<double>(m1 + m2) / (2 * spm), static_cast<double>(m1 - m2) / (2 * spm)}; };
  while (std::getline(job, l)) {
    long long b = 0, c = 0;
    if (move_steps(l, b, c)) {
      m1 += b, m2 += c;
      if (down && (b || c)) out.back().push_back(here());
    } else if (l.rfind("SP,0", 0) == 0 && !down) {
      down = true;
      out.push_back({here()});
    } else if (l.rfind("SP,1", 0) == 0) {
      down = false;
    } else if (l.rfind("EM", 0) == 0) {
      m1 = m2 = 0;
    }
  }
  return out;
}

size_t job_down_steps(const std::string& job_path) {
  std::istringstream job(slurp(job_path));
  std::string l;
  bool down = false;
  size_t n = 0;
  while (std::getline(job, l)) {
    long long b = 0, c = 0;
    if (move_steps(l, b, c) && down) n += static_cast<size_t>(std::llabs(b) + std::llabs(c));
    if (l.rfind("SP,0", 0) == 0) down = true;
    if (l.rfind("SP,1", 0) == 0) down = false;
  }
  return n;
}

std::vector<Path> planned_strokes(const std::string& svg_path) {
  const std::string svg = slurp(svg_path);
  bool last_full = false;  // the last path had kMaxElementPoints points: a stroke may go on
  std::vector<Path> out;
  static const std::regex element(R"re(<path d="([^"]*)"|<circle cx="([-0-9.e]+)" cy="([-0-9.e]+)")re");
  static const std::regex pair(R"re(([-0-9.e]+),([-0-9.e]+))re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), element); it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    if (m[1].matched) {
      const std::string d = m[1];
      Path p;
      for (auto q = std::sregex_iterator(d.begin(), d.end(), pair); q != std::sregex_iterator(); ++q)
        p.push_back({std::stod((*q)[1]), std::stod((*q)[2])});
      // A stroke of more than kMaxElementPoints is written as consecutive paths, each
      // starting where the last ended: one stroke again. Only a full piece continues (two
      // strokes of their own may meet end to start: foreign.svg's do).
      const bool continues = last_full && !p.empty() && out.back().back().x == p.front().x &&
                             out.back().back().y == p.front().y;
      last_full = p.size() == stipplot::kMaxElementPoints;
      if (continues) {
        out.back().insert(out.back().end(), p.begin() + 1, p.end());
        continue;
      }
      out.push_back(p);
    } else {
      last_full = false;
      out.push_back({{std::stod(m[2]), std::stod(m[3])}});
    }
  }
  return out;
}

Comparison compare_marks(const std::vector<Path>& plan, const std::vector<Path>& drawn, double tol) {
  Comparison c;
  c.plan_marks = plan.size();
  c.drawn_marks = drawn.size();
  if (plan.size() != drawn.size()) {
    c.why = "the plan has " + std::to_string(plan.size()) + " marks, the firmware drew " + std::to_string(drawn.size());
    return c;
  }
  for (size_t i = 0; i < plan.size(); ++i) {
    for (const Pt& p : drawn[i]) c.worst = std::max(c.worst, path_dist(p, plan[i]));
    for (const Pt& p : plan[i]) c.worst = std::max(c.worst, path_dist(p, drawn[i]));
    if (c.worst > tol && c.why.empty()) {
      char b[160];
      std::snprintf(b, sizeof b, "mark %zu (from %.3f,%.3f) is %.4f mm from the plan", i + 1, plan[i][0].x, plan[i][0].y,
                    c.worst);
      c.why = b;
    }
  }
  c.ok = c.why.empty();
  return c;
}

namespace {
// Every vertex of the paths and a point at most `step` mm apart along them.
template <class F>
void each_point(const std::vector<Path>& paths, double step, F f) {
  for (const Path& p : paths) {
    if (!p.empty()) f(p[0]);
    for (size_t i = 1; i < p.size(); ++i) {
      const double len = std::hypot(p[i].x - p[i - 1].x, p[i].y - p[i - 1].y);
      const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
      for (int k = 1; k <= n; ++k)
        f(Pt{p[i - 1].x + (p[i].x - p[i - 1].x) * k / n, p[i - 1].y + (p[i].y - p[i - 1].y) * k / n});
    }
  }
}
}  // namespace

Gap farthest(const std::vector<Path>& a, const std::vector<Path>& b, double step, double cap) {
  auto key = [cap](double x, double y) {
    return (static_cast<int64_t>(std::floor(x / cap)) << 32) ^ (static_cast<int64_t>(std::floor(y / cap)) & 0xffffffff);
  };
  std::unordered_map<int64_t, std::vector<Pt>> grid;
  each_point(b, step, [&](Pt p) { grid[key(p.x, p.y)].push_back(p); });
  Gap g;
  each_point(a, step, [&](Pt p) {
    double d = cap;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy) {
        const auto it = grid.find(key(p.x + dx * cap, p.y + dy * cap));
        if (it == grid.end()) continue;
        for (const Pt& q : it->second) d = std::min(d, std::hypot(p.x - q.x, p.y - q.y));
      }
    if (d > g.worst) g = {d, p};
  });
  return g;
}

EbbBoard::EbbBoard(const std::string& log, bool realtime, const std::string& flash) {
  const std::string exe = ensure_ebb_sim();
  std::vector<const char*> argv{exe.c_str(), "-l", log.c_str()};
  if (realtime) argv.push_back("-r");
  if (!flash.empty()) argv.insert(argv.end(), {"-f", flash.c_str()});
  argv.push_back(nullptr);
  int in[2], out[2];
  if (::pipe2(in, O_CLOEXEC) != 0 || ::pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  pid_ = ::fork();
  if (pid_ == 0) {
    ::dup2(in[0], 0);
    ::dup2(out[1], 1);
    ::execv(exe.c_str(), const_cast<char* const*>(argv.data()));
    ::_exit(127);
  }
  ::close(in[0]);
  ::close(out[1]);
  to_fw_ = in[1];
  from_fw_ = out[0];
  ::fcntl(from_fw_, F_SETFL, O_NONBLOCK);
  open_pty();
  thread_ = std::thread([this] { relay(); });
}

EbbBoard::~EbbBoard() {
  try {
    finish();
  } catch (...) {
  }
}

void EbbBoard::open_pty() {
  const int m = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (m < 0 || ::grantpt(m) != 0 || ::unlockpt(m) != 0) throw std::runtime_error("no pty");
  ::fcntl(m, F_SETFL, O_NONBLOCK);
  std::lock_guard<std::mutex> lk(mu_);
  if (master_ >= 0) ::close(master_);  // the old link (a killed client's) goes
  master_ = m;
  port_ = ::ptsname(m);
  dropped_ = false;
}

void EbbBoard::reboot() {
  if (::write(to_fw_, "RB\r", 3) != 3) throw std::runtime_error("cannot write RB to ebb_sim");
}

std::string EbbBoard::reconnect() {
  open_pty();
  return port_;
}

void EbbBoard::relay() {
  std::string to_client;
  while (!stop_) {
    int m;
    {
      std::lock_guard<std::mutex> lk(mu_);
      m = master_;
    }
    pollfd p[2] = {{from_fw_, POLLIN, 0}, {m, POLLIN, 0}};
    ::poll(p, m >= 0 ? 2 : 1, 5);
    // A pty nobody holds open polls as hung up all the time: look again in 2 ms.
    if (m >= 0 && (p[1].revents & POLLHUP)) ::usleep(2000);
    char buf[4096];
    ssize_t n;
    while ((n = ::read(from_fw_, buf, sizeof buf)) > 0) {
      forward_from_firmware(buf, static_cast<size_t>(n));
      if (m >= 0) [[maybe_unused]] ssize_t w = ::write(m, buf, static_cast<size_t>(n));  // lost while the link is down
    }
    if (m < 0) continue;
    n = ::read(m, buf, sizeof buf);
    if (n <= 0) continue;  // nobody has the pty open yet, or nothing sent
    size_t k = 0;
    for (; k < static_cast<size_t>(n); ++k) {
      if (buf[k] != '\r') continue;
      if (++commands_ == drop_after_) {
        ++k;
        break;
      }
    }
    for (size_t i = 0; i < k; ++i) {  // the names of the commands sent, for the answers' pairing
      if (buf[i] == '\r') {
        unanswered_.push_back(sending_.substr(0, sending_.find(',')));
        sending_.clear();
      } else if (buf[i] != '\n') {
        sending_ += buf[i];
      }
    }
    [[maybe_unused]] ssize_t w = ::write(to_fw_, buf, k);
    if (drop_after_ && commands_ >= drop_after_ && !dropped_) {
      // The board reboots there (reset_after_commands): the firmware's own RB.
      if (reset_.exchange(false)) [[maybe_unused]] ssize_t r = ::write(to_fw_, "RB\r", 3);
      // The cable is pulled: the rest is lost and the client's pty hangs up. Said before the
      // hang-up: the client exits on it, and its test asks dropped() at once.
      dropped_ = true;
      drop_after_ = 0;
      std::lock_guard<std::mutex> lk(mu_);
      ::close(master_);
      master_ = -1;
    }
  }
}

// Pairs the firmware's answer lines with the commands sent (legacy replies: data lines,
// then "OK"; V answers with its version line alone) and, once the button is pressed, turns
// the next QB's "0" into "1" in place.
void EbbBoard::forward_from_firmware(char* buf, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    const char c = buf[i];
    if (c == '\r' || c == '\n') {
      if (reading_.empty()) continue;
      if (!unanswered_.empty() && (reading_ == "OK" || unanswered_.front() == "V")) unanswered_.pop_front();
      reading_.clear();
      continue;
    }
    if (reading_.empty() && c == '0' && press_after_ && commands_ >= press_after_ && !unanswered_.empty() &&
        unanswered_.front() == "QB") {
      buf[i] = '1';
      pressed_ = true;
      press_after_ = 0;
    }
    reading_ += buf[i];
  }
}

void EbbBoard::finish() {
  if (pid_ < 0) return;
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  ::close(to_fw_);  // EOF: the firmware exits once idle
  int st = 0;
  for (int i = 0; i < 6000 && ::waitpid(pid_, &st, WNOHANG) == 0; ++i) {
    char buf[4096];
    while (::read(from_fw_, buf, sizeof buf) > 0) {
    }
    ::usleep(10000);
  }
  if (::waitpid(pid_, &st, WNOHANG) == 0) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, &st, 0);
  }
  ::close(from_fw_);
  if (master_ >= 0) ::close(master_);
  pid_ = -1;
}

}  // namespace ebbtest
