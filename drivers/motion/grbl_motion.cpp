#include "drivers/motion/grbl_motion.hpp"

#include <algorithm>
#include <cmath>

#include "util/error.hpp"

namespace stipplot::motion {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinFeedMmS = 1.0 / 60;  // grbl's MINIMUM_FEED_RATE, 1 mm/min
}  // namespace

double grbl_dwell_seconds(double p) {
  if (!(p > 0)) return 0;
  // delay_sec(): ceil(1000 / DWELL_TIME_STEP * seconds) steps of 50 ms, in float.
  const float steps = 20.0f * static_cast<float>(p);
  return std::ceil(static_cast<double>(steps)) * 0.05;
}

GrblMotion::GrblMotion(const GrblSettings& s) : s_(s) {
  for (int i = 0; i < 3; ++i) {
    require_range("steps_per_mm", s.steps_per_mm[i], 1e-3, 1e6);
    require_range("max_rate_mm_min", s.max_rate_mm_min[i], 1e-3, 1e7);
    require_range("accel_mm_s2", s.accel_mm_s2[i], 1e-3, 1e8);
  }
  require_range("junction_deviation_mm", s.junction_deviation_mm, 0, 100);
  require_range("idle_lock_s", s.idle_lock_s, 0, 1);
  require_range("planner_blocks", s.planner_blocks, 1, 10000);
}

double GrblMotion::limit_by_axes(const Vec3& values, const Vec3& unit) const {
  double limit = kInf;
  for (int i = 0; i < 3; ++i)
    if (unit[i] != 0) limit = std::min(limit, std::fabs(values[i] / unit[i]));
  return limit;
}

bool GrblMotion::plan(const Vec3& target, double feed_mm_min, bool rapid, long tag, double t) {
  advance(t);
  GrblBlock b;
  b.from = planner_pos_;
  int64_t events = 0;
  Vec3 delta{};
  for (int i = 0; i < 3; ++i) {
    b.to[i] = std::llround(target[i] * s_.steps_per_mm[i]);
    events = std::max<int64_t>(events, std::llabs(b.to[i] - b.from[i]));
    delta[i] = static_cast<double>(b.to[i] - b.from[i]) / s_.steps_per_mm[i];
  }
  if (events == 0) return false;  // grbl: PLAN_EMPTY_BLOCK
  b.mm = std::sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
  for (int i = 0; i < 3; ++i) b.unit[i] = delta[i] / b.mm;
  b.accel = limit_by_axes(s_.accel_mm_s2, b.unit);
  const Vec3 rate{s_.max_rate_mm_min[0] / 60, s_.max_rate_mm_min[1] / 60, s_.max_rate_mm_min[2] / 60};
  const double rapid_rate = limit_by_axes(rate, b.unit);
  b.rapid = rapid;
  b.nominal = rapid ? rapid_rate : std::max(kMinFeedMmS, std::min(feed_mm_min / 60, rapid_rate));
  b.tag = tag;
  b.target = target;
  double max_junction_sqr = 0;
  if (!blocks_.empty()) {
    // Junction deviation: the corner speed of a circle tangent to both moves, with the
    // per-axis acceleration along the junction vector (planner.c).
    double cos_theta = 0;
    Vec3 j{};
    for (int i = 0; i < 3; ++i) {
      cos_theta -= prev_unit_[i] * b.unit[i];
      j[i] = b.unit[i] - prev_unit_[i];
    }
    if (cos_theta > 0.999999) {
      max_junction_sqr = 0;
    } else if (cos_theta < -0.999999) {
      max_junction_sqr = kInf;
    } else {
      const double jl = std::sqrt(j[0] * j[0] + j[1] * j[1] + j[2] * j[2]);
      for (double& c : j) c /= jl;
      const double ja = limit_by_axes(s_.accel_mm_s2, j);
      const double sin_half = std::sqrt(0.5 * (1.0 - cos_theta));
      max_junction_sqr = ja * s_.junction_deviation_mm * sin_half / (1.0 - sin_half);
    }
  }
  const double lim = std::min(b.nominal, prev_nominal_);
  b.max_entry_sqr = std::min(lim * lim, max_junction_sqr);
  prev_nominal_ = b.nominal;
  prev_unit_ = b.unit;
  planner_pos_ = b.to;
  const bool was_empty = blocks_.empty();
  blocks_.push_back(b);
  if (was_empty) {
    done_mm_ = 0;
    v_ = 0;
    hold_stopped_ = false;
    rest_starts_.push_back(std::max(now_, idle_until_));
    start_not_before_ = rest_starts_.back() + last_tick_s_;  // the first interrupt comes one old period late
  }
  replan();
  if (!hold_) profile_current();
  else if (was_empty) hold_stopped_ = true;  // planned during a hold: waits for the resume
  if (first_start_ < 0) first_start_ = rest_starts_.back();
  return true;
}

// planner_recalculate(): the newest block ends at rest; reverse pass from it, forward pass
// from the running block, whose entry is its current speed over what it has left.
void GrblMotion::replan() {
  const size_t n = blocks_.size();
  if (n < 2) return;
  GrblBlock& last = blocks_[n - 1];
  last.entry_sqr = std::min(last.max_entry_sqr, 2 * last.accel * last.mm);
  for (size_t i = n - 2; i >= 1; --i) {
    GrblBlock& c = blocks_[i];
    c.entry_sqr = std::min(c.max_entry_sqr, blocks_[i + 1].entry_sqr + 2 * c.accel * c.mm);
  }
  double prev_entry = v_ * v_, prev_mm = blocks_[0].mm - done_mm_, prev_accel = blocks_[0].accel;
  for (size_t i = 1; i < n; ++i) {
    GrblBlock& c = blocks_[i];
    c.entry_sqr = std::min(c.entry_sqr, prev_entry + 2 * prev_accel * prev_mm);
    prev_entry = c.entry_sqr;
    prev_mm = c.mm;
    prev_accel = c.accel;
  }
}

double GrblMotion::exit_sqr_of_current() const { return blocks_.size() > 1 ? blocks_[1].entry_sqr : 0.0; }

// The running block's profile from its speed now over what it has left: accelerate,
// cruise, decelerate to the exit speed the plan gives (in a hold: decelerate to rest).
void GrblMotion::profile_current() {
  phases_.clear();
  if (blocks_.empty()) return;
  const GrblBlock& b = blocks_[0];
  seg_t0_ = std::max(now_, done_mm_ == 0 && v_ == 0 ? start_not_before_ : now_);
  seg_mm0_ = done_mm_;
  const double L = std::max(0.0, b.mm - done_mm_), a = b.accel, v0 = v_;
  auto push = [&](double v_start, double v_end, double dist) {
    if (!(dist > 0)) return;
    if (std::fabs(v_end - v_start) < 1e-12) {
      if (v_start > 0) phases_.push_back({dist / v_start, 0, v_start, dist});
      return;
    }
    const double acc = v_end > v_start ? a : -a;
    phases_.push_back({(v_end - v_start) / acc, acc, v_start, dist});
  };
  if (hold_) {
    const double stop_d = v0 * v0 / (2 * a);
    if (stop_d <= L) push(v0, 0, stop_d);
    else push(v0, std::sqrt(std::max(0.0, v0 * v0 - 2 * a * L)), L);
    return;
  }
  const double ve_sqr = exit_sqr_of_current(), vmax = std::max(b.nominal, 1e-9);
  if (v0 * v0 >= ve_sqr + 2 * a * L) {  // cannot even slow to the exit speed: decelerate all the way
    push(v0, std::sqrt(std::max(0.0, v0 * v0 - 2 * a * L)), L);
    return;
  }
  if (v0 * v0 + 2 * a * L <= ve_sqr) {  // cannot reach the exit speed: accelerate all the way
    push(v0, std::sqrt(v0 * v0 + 2 * a * L), L);
    return;
  }
  const double ve = std::sqrt(ve_sqr);
  const double vc = std::max(v0, vmax);
  const double d_acc = std::max(0.0, (vc * vc - v0 * v0) / (2 * a)), d_dec = (vc * vc - ve_sqr) / (2 * a);
  if (d_acc + d_dec <= L) {
    push(v0, vc, d_acc);
    push(vc, vc, L - d_acc - d_dec);
    push(vc, ve, d_dec);
  } else {
    const double vp = std::sqrt((2 * a * L + v0 * v0 + ve_sqr) / 2);
    push(v0, vp, (vp * vp - v0 * v0) / (2 * a));
    push(vp, ve, (vp * vp - ve_sqr) / (2 * a));
  }
}

double GrblMotion::next_event() const {
  if (blocks_.empty()) return idle_until_ > now_ ? idle_until_ : kInf;
  if (hold_stopped_) return kInf;
  double end = seg_t0_;
  for (const Phase& p : phases_) end += p.t;
  return std::max(end, now_);
}

namespace {
// The stepper timer's period over the last 10 ms segment of a stop at acceleration a:
// the distance a*dt^2/2 in whole step events along the dominant axis.
double final_tick_seconds(const GrblBlock& b, const Vec3& steps_per_mm) {
  double events_per_mm = 0;
  for (int i = 0; i < 3; ++i) events_per_mm = std::max(events_per_mm, std::fabs(b.unit[i]) * steps_per_mm[i]);
  constexpr double dt = 0.01;  // DT_SEGMENT: 1 / ACCELERATION_TICKS_PER_SECOND
  const double steps = std::ceil(0.5 * b.accel * dt * dt * events_per_mm);
  return dt / std::max(1.0, steps);
}
}  // namespace

void GrblMotion::finish_current(double t) {
  const GrblBlock b = blocks_.front();
  // Speed at the end of its phases (the exit speed).
  double v = v_;
  if (!phases_.empty()) v = phases_.back().v0 + phases_.back().a * phases_.back().t;
  blocks_.pop_front();
  for (int i = 0; i < 3; ++i) rest_pos_[i] = static_cast<double>(b.to[i]) / s_.steps_per_mm[i];
  finished_.push_back({b.tag, t, rest_pos_, b.target});
  now_ = t;
  done_mm_ = 0;
  if (blocks_.empty()) {
    v_ = 0;
    phases_.clear();
    ++stops_;
    last_tick_s_ = final_tick_seconds(b, s_.steps_per_mm);
    idle_until_ = t + last_tick_s_ + s_.idle_lock_s;  // st_go_idle(): the stepper idle lock busy-waits
    idle_total_ += s_.idle_lock_s;
    if (hold_) hold_stopped_ = false;
    return;
  }
  v_ = std::max(0.0, v);
  if (!hold_) replan();
  profile_current();
}

void GrblMotion::advance(double t) {
  if (t < now_) t = now_;
  while (!blocks_.empty() && !hold_stopped_) {
    const double end = next_event();
    if (end > t) break;
    const double L = blocks_[0].mm - done_mm_;
    double covered = 0;
    for (const Phase& p : phases_) covered += p.dist;
    if (hold_ && covered < L - 1e-9) {  // the hold has brought it to rest inside the block
      done_mm_ += covered;
      v_ = 0;
      now_ = end;
      phases_.clear();
      hold_stopped_ = true;
      break;
    }
    finish_current(end);
  }
  if (!blocks_.empty() && !hold_stopped_ && t > seg_t0_) {
    // Re-anchor the profile at t: drop the phases that have run, shorten the one under way.
    double dt = t - seg_t0_;
    size_t k = 0;
    for (; k < phases_.size() && dt > 0; ++k) {
      Phase& p = phases_[k];
      if (dt < p.t) {
        const double d = p.v0 * dt + 0.5 * p.a * dt * dt;
        done_mm_ += d;
        p.dist -= d;
        p.v0 += p.a * dt;
        p.t -= dt;
        v_ = p.v0;
        dt = 0;
        break;
      }
      done_mm_ += p.dist;
      v_ = p.v0 + p.a * p.t;
      dt -= p.t;
    }
    phases_.erase(phases_.begin(), phases_.begin() + static_cast<long>(k));
    done_mm_ = std::min(done_mm_, blocks_[0].mm);
    v_ = std::max(0.0, v_);
    seg_t0_ = t;
    seg_mm0_ = done_mm_;
  }
  now_ = t;
}

Vec3 GrblMotion::position() const {
  if (blocks_.empty()) return rest_pos_;
  const GrblBlock& b = blocks_[0];
  Vec3 p{};
  for (int i = 0; i < 3; ++i) p[i] = static_cast<double>(b.from[i]) / s_.steps_per_mm[i] + b.unit[i] * done_mm_;
  return p;
}

void GrblMotion::hold(double t) {
  advance(t);
  if (hold_) return;
  hold_ = true;
  if (blocks_.empty()) return;
  if (v_ <= 0 && done_mm_ == 0) {
    hold_stopped_ = true;  // not started yet
    phases_.clear();
    return;
  }
  profile_current();
}

void GrblMotion::resume(double t) {
  advance(t);
  if (!hold_) return;
  hold_ = false;
  hold_stopped_ = false;
  if (blocks_.empty()) return;
  // plan_cycle_reinitialize(): re-plan from a complete stop.
  if (v_ <= 1e-9) v_ = 0;
  replan();
  profile_current();
}

void GrblMotion::halt() {
  const Vec3 p = position();
  blocks_.clear();
  phases_.clear();
  v_ = 0;
  done_mm_ = 0;
  hold_ = hold_stopped_ = false;
  idle_until_ = -kInf;
  set_position(p);
}

void GrblMotion::set_position(const Vec3& mm) {
  for (int i = 0; i < 3; ++i) planner_pos_[i] = std::llround(mm[i] * s_.steps_per_mm[i]);
  for (int i = 0; i < 3; ++i) rest_pos_[i] = static_cast<double>(planner_pos_[i]) / s_.steps_per_mm[i];
  prev_nominal_ = 0;
}

std::vector<GrblMotion::Finished> GrblMotion::take_finished() {
  std::vector<Finished> out;
  out.swap(finished_);
  return out;
}

}  // namespace stipplot::motion
