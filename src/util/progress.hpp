#pragma once
// A terminal progress bar with percent, elapsed time and ETA, drawn on stderr only
// when stderr is a terminal (so logs and --json output stay clean).
#include <chrono>
#include <cstdint>
#include <string>

namespace stipplot {

class Progress {
 public:
  Progress(std::string label, uint64_t total, bool enabled);
  ~Progress();
  // Cheap to call often: redraws at most ~10 times a second.
  void update(uint64_t done);
  // Optional externally supplied ETA in seconds (e.g. from a time model); < 0 = derive.
  void set_eta_hint(double seconds) { eta_hint_ = seconds; }
  void set_suffix(std::string s) { suffix_ = std::move(s); }
  // Ends the bar: at 100 % when the work completed, where it stopped when not (an abort
  // or a fault must not read as done).
  void finish(bool completed = true);
  static bool stderr_is_tty();

 private:
  void draw(bool final);
  std::string label_;
  uint64_t total_, done_ = 0;
  bool enabled_, finished_ = false;
  size_t last_len_ = 0;  // the longest line drawn: a shorter one is padded over it
  double eta_hint_ = -1;
  std::string suffix_;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

std::string format_duration(double seconds);

}  // namespace stipplot
