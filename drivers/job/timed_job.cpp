#include "drivers/job/timed_job.hpp"

#include "drivers/job/ebb_reader.hpp"

#include <algorithm>
#include <deque>
#include <cmath>
#include <limits>

#include "drivers/job/gcode_state.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "drivers/motion/ebb_motion.hpp"

namespace stipplot::io {

// The grbl machine fed by a host streaming with character counting: a line reaches the
// parser when the host had room to send it and the wire has carried it; a move waits
// for room in the planner, a sync line for the machine to stop; the answer ("ok") frees
// the line's bytes for the host.
struct GcodeTimer::Impl {
  Impl(const motion::GrblSettings& s, const GcodeLink& l) : m(s), link(l) {}

  void feed(std::string_view text) {
    const size_t i = t.done_s.size();
    t.done_s.push_back(-1);
    window.push_back({text.size() + 1, 0.0});
    const double arrives = arrival();
    if (arrives > now) run_until([] { return false; }, arrives);
    now = std::max(now, arrives);
    const GcodeEffect e = st.apply(text);
    if (e.syncs()) {
      run_until([&] { return !m.busy(); });
      if (e.dwell) now += motion::grbl_dwell_seconds(e.dwell_p);
      if (e.pause) ++t.pauses;
      t.done_s[i] = now;
    } else if (e.move) {
      run_until([&] { return m.has_room(); });
      if (!m.plan(e.target, e.feed_mm_min, e.rapid, static_cast<long>(i), now)) t.done_s[i] = now;
    } else {
      t.done_s[i] = now;
    }
    window.back().acked = now;  // grbl answers when the parser is done with the line
  }

  JobTiming finish() {
    run_until([&] { return !m.moving(); });
    t.motion_start_s = m.first_motion_s();
    t.starts_from_rest = m.starts_from_rest();
    t.stops = m.stops();
    t.idle_lock_s = m.idle_lock_total_s();
    double last = 0;
    for (double& d : t.done_s) last = d = std::max(d, last);  // a modal line is done with the line before it
    t.total_s = last;
    return t;
  }

  // When the newest line is in grbl's receive buffer: the host sends it once the
  // unanswered lines before it and it fit the buffer (their answers travel back over the
  // wire), and the wire is free.
  double arrival() {
    if (!(link.baud > 0)) {
      window.erase(window.begin(), window.end() - 1);
      return 0;
    }
    const double byte_s = 10.0 / link.baud, answer_s = 4 * byte_s + link.latency_s;
    const size_t bytes = window.back().bytes;
    double at = wire_free;
    while (window.size() > 1 && window_bytes + bytes > static_cast<size_t>(link.rx_buffer)) {
      at = std::max(at, window.front().acked + answer_s);
      window_bytes -= window.front().bytes;
      window.pop_front();
    }
    window_bytes += bytes;
    wire_free = at + static_cast<double>(bytes) * byte_s;
    return wire_free + link.latency_s;
  }

  template <class Pred>
  void run_until(Pred ready, double until = std::numeric_limits<double>::infinity()) {
    while (!ready()) {
      const double next = m.next_event();
      if (!std::isfinite(next) || next > until) {
        if (std::isfinite(until)) m.advance(until);
        break;
      }
      now = std::max(now, next);
      m.advance(now);
      for (const auto& f : m.take_finished()) {
        t.done_s[static_cast<size_t>(f.tag)] = f.t;
        t.motion_end_s = f.t;
      }
    }
  }

  motion::GrblMotion m;
  GcodeLink link;
  GcodeState st;
  JobTiming t;
  // The lines sent whose answers the host has not yet counted, the newest last: their
  // bytes and when grbl answered (only these, not every line: 5M lines of 1M dots).
  struct Sent {
    size_t bytes;
    double acked;
  };
  std::deque<Sent> window;
  std::string scratch;  // a line cleaned of its comment
  double now = 0, wire_free = 0;
  size_t window_bytes = 0;
};

GcodeTimer::GcodeTimer(const motion::GrblSettings& machine, const GcodeLink& link)
    : impl_(std::make_unique<Impl>(machine, link)) {}
GcodeTimer::~GcodeTimer() = default;

void GcodeTimer::feed(std::string_view raw_line) {
  const std::string_view text = gcode_line_view(raw_line, impl_->scratch);
  if (!text.empty()) impl_->feed(text);
}

size_t GcodeTimer::lines() const { return impl_->t.done_s.size(); }

void GcodeTimer::reserve(size_t lines) { impl_->t.done_s.reserve(lines); }

JobTiming GcodeTimer::finish() { return impl_->finish(); }

JobTiming time_gcode_job(const Job& job, const motion::GrblSettings& machine, const GcodeLink& link) {
  GcodeTimer timer(machine, link);
  for (const JobLine& l : job.lines) timer.feed(l.text);
  return timer.finish();
}

HpglTimer::HpglTimer(const motion::HpglMotion& plotter) : m_(plotter), vs_(plotter.speed_down_mm_s) {}

void HpglTimer::feed(std::string_view instruction, bool host_only, bool pause) {
  if (pause) ++t_.pauses;
  if (host_only || instruction.size() < 2 || instruction[0] == 0x1b) {
    t_.done_s.push_back(now_);
    return;
  }
  const std::string mn(instruction.substr(0, 2));
  std::string_view params = instruction.substr(2);
  if (!params.empty() && params.back() == ';') params.remove_suffix(1);
  const std::vector<double> nums = hpgl_numbers(params);
  const bool was_down = down_;
  const bool plot = mn == "PU" || mn == "PD" || mn == "PA" || mn == "PR";
  if (mn == "IN") {
    down_ = false, absolute_ = true, vs_ = m_.speed_down_mm_s;
  } else if (mn == "SP") {
    down_ = false;
    now_ += m_.pen_change_s;
  } else if (mn == "VS") {
    if (!nums.empty() && nums[0] > 0) vs_ = nums[0] * 10;
  } else if (plot) {
    if (mn == "PU") down_ = false;
    if (mn == "PD") down_ = true;
    if (mn == "PA") absolute_ = true;
    if (mn == "PR") absolute_ = false;
  }
  // The pen moves first (as the simulated plotter does it), then the points.
  if (down_ != was_down) now_ += down_ ? m_.pen_drop_s : m_.pen_lift_s;
  if (plot) {
    for (size_t k = 0; k + 1 < nums.size(); k += 2) {
      const double nx = absolute_ ? nums[k] : x_ + nums[k], ny = absolute_ ? nums[k + 1] : y_ + nums[k + 1];
      const double dt = motion::hpgl_move_seconds(m_, nx - x_, ny - y_, down_ ? vs_ : m_.speed_up_mm_s);
      if (dt > 0 && t_.motion_start_s < 0) t_.motion_start_s = now_;
      now_ += dt;
      if (dt > 0) t_.motion_end_s = now_;
      x_ = nx, y_ = ny;
    }
  }
  t_.done_s.push_back(now_);
  t_.total_s = now_;
}

JobTiming time_hpgl_job(const Job& job, const motion::HpglMotion& plotter) {
  HpglTimer timer(plotter);
  for (const JobLine& l : job.lines) timer.feed(l.text, l.host_only, l.pause);
  return timer.finish();
}

void EbbTimer::feed(std::string_view line, bool host_only, bool pause) {
  if (pause) ++t_.pauses;
  if (!host_only) {
    const EbbCommand c = parse_ebb_command(line, t_.done_s.size() + 1);
    const bool move = ebb_motion_command(c.name) && (c.s1 != 0 || c.s2 != 0);
    const double now = static_cast<double>(now_ticks_) / motion::kEbbTicksPerS;
    if (move && t_.motion_start_s < 0) t_.motion_start_s = now;
    if (move && !moving_) t_.starts_from_rest.push_back(now);
    if (ebb_motion_command(c.name) || c.name == "SP") {
      if (moving_ && !move) ++t_.stops;
      moving_ = move;
    }
    now_ticks_ += c.ticks;
    if (move) t_.motion_end_s = static_cast<double>(now_ticks_) / motion::kEbbTicksPerS;
  }
  t_.done_s.push_back(static_cast<double>(now_ticks_) / motion::kEbbTicksPerS);
  t_.total_s = static_cast<double>(now_ticks_) / motion::kEbbTicksPerS;
}

JobTiming time_ebb_job(const Job& job) {
  EbbTimer timer;
  for (const JobLine& l : job.lines) timer.feed(l.text, l.host_only, l.pause);
  return timer.finish();
}

void apply_timing(Job& job, const JobTiming& t) {
  double prev = 0;
  for (size_t i = 0; i < job.lines.size() && i < t.done_s.size(); ++i) {
    job.lines[i].done_s = t.done_s[i];
    job.lines[i].est_s = t.done_s[i] - prev;
    prev = t.done_s[i];
  }
  job.est_total_s = t.total_s;
}

double seconds_after(const Job& job, long line) {
  if (line < 0 || job.lines.empty()) return job.est_total_s;
  const size_t i = std::min(static_cast<size_t>(line), job.lines.size() - 1);
  return std::max(0.0, job.est_total_s - job.lines[i].done_s);
}

}  // namespace stipplot::io
