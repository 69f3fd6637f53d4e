#include "util/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace stipplot {

bool Progress::stderr_is_tty() { return ::isatty(STDERR_FILENO) == 1; }

std::string format_duration(double s) {
  if (!std::isfinite(s) || s < 0) return "--:--";
  long t = std::lround(s);
  char buf[32];
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%02ld:%02ld", t / 60, t % 60);
  return buf;
}

Progress::Progress(std::string label, uint64_t total, bool enabled)
    : label_(std::move(label)), total_(total), enabled_(enabled && stderr_is_tty()),
      start_(std::chrono::steady_clock::now()), last_draw_(start_) {}

Progress::~Progress() {
  if (!finished_) finish(false);  // left by an exception: where it stopped
}

void Progress::update(uint64_t done) {
  done_ = done;
  if (!enabled_) return;
  auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(false);
}

void Progress::finish(bool completed) {
  if (finished_) return;
  finished_ = true;
  if (!enabled_) return;
  if (completed) done_ = total_;
  draw(true);
  std::fputc('\n', stderr);
}

void Progress::draw(bool /*final*/) {
  using namespace std::chrono;
  double elapsed = duration<double>(steady_clock::now() - start_).count();
  double frac = total_ ? static_cast<double>(done_) / static_cast<double>(total_) : 1.0;
  double eta = eta_hint_ >= 0 ? eta_hint_ : (frac > 1e-9 ? elapsed * (1 - frac) / frac : -1);
  constexpr int width = 30;
  int filled = static_cast<int>(frac * width);
  std::string bar(static_cast<size_t>(filled), '#');
  bar.resize(width, '-');
  char line[512];
  std::snprintf(line, sizeof line, "%s [%s] %5.1f%% %s elapsed, ETA %s %s", label_.c_str(), bar.c_str(), 100 * frac,
                format_duration(elapsed).c_str(), format_duration(eta).c_str(), suffix_.c_str());
  const size_t len = std::strlen(line);
  // Spaces over what a longer earlier line left ("Idle" after "Hold:0" must not read "Idleld:0").
  std::fprintf(stderr, "\r%s%*s", line, static_cast<int>(last_len_ > len ? last_len_ - len : 0), "");
  last_len_ = std::max(last_len_, len);
  std::fflush(stderr);
}

}  // namespace stipplot
