#include "drivers/motion/time_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "util/error.hpp"
#include "util/threads.hpp"

namespace stipplot::motion {

double axis_limited_accel(double accel, Vec2 u) {
  const double m = std::max(std::fabs(u.x), std::fabs(u.y));
  return m > 0 ? accel / m : accel;
}

double junction_speed_sqr(Vec2 u_in, Vec2 u_out, const MotionParams& m) {
  // grbl 1.1 planner.c: cos of the angle between the reversed entry and the exit.
  const double cos_theta = -(u_in.x * u_out.x + u_in.y * u_out.y);
  if (cos_theta > 0.999999) return 0;  // reversal: stop
  if (cos_theta < -0.999999) return std::numeric_limits<double>::infinity();  // straight on
  Vec2 j{u_out.x - u_in.x, u_out.y - u_in.y};
  const double jl = std::hypot(j.x, j.y);
  j = {j.x / jl, j.y / jl};
  const double a = axis_limited_accel(m.accel_mm_s2, j);
  const double sin_half = std::sqrt(0.5 * (1.0 - cos_theta));
  return a * m.junction_deviation_mm * sin_half / (1.0 - sin_half);
}

double trapezoid_seconds(double L, double v0, double v1, double vmax, double a, double* v_peak) {
  if (!(L > 0)) {
    if (v_peak) *v_peak = std::max(v0, v1);
    return 0;
  }
  const double d_acc = (vmax * vmax - v0 * v0) / (2 * a);
  const double d_dec = (vmax * vmax - v1 * v1) / (2 * a);
  if (d_acc + d_dec <= L) {
    if (v_peak) *v_peak = vmax;
    return (vmax - v0) / a + (vmax - v1) / a + (L - d_acc - d_dec) / vmax;
  }
  // Triangle: accelerate to vp, then decelerate; vp^2 = (2aL + v0^2 + v1^2) / 2.
  const double vp = std::sqrt(std::max(0.0, (2 * a * L + v0 * v0 + v1 * v1) / 2));
  if (v_peak) *v_peak = vp;
  return std::max(0.0, vp - v0) / a + std::max(0.0, vp - v1) / a;
}

namespace {

// A polyline's segments of non-zero length in order (grbl drops zero-length blocks), each
// with what the planner knows of it, kept in a window of the planner's look-ahead.
struct Seg {
  Vec2 from, to, u;
  double L, a, max_entry_sqr;
  size_t end;  // the index of its end point
};

class SegmentWindow {
 public:
  // Streams the segments ending at point `first_end` on; `prev_u` the direction of the
  // segment before them (none at the polyline's start).
  SegmentWindow(const std::vector<Vec2>& pts, double vmax, const MotionParams& m, size_t first_end,
                const Vec2* prev_u)
      : pts_(pts), vmax_(vmax), m_(m), next_(first_end),
        // Only the planner's window of segments is kept, not one per point: a 900,000-point
        // outline would otherwise take 65 MB of fresh pages on each timing (the budget times a
        // plan several times). The window is written twice over (at p and p + cap) so that
        // blocks i .. i+B-1 are always contiguous.
        B_(static_cast<size_t>(std::max(1, m.lookahead_blocks))),
        cap_(std::max<size_t>(1, std::min(B_, pts.size()))), window_(2 * cap_) {
    if (prev_u) prev_u_ = *prev_u, have_prev_ = true;
  }
  // Fills the window to B segments (fewer at the polyline's end); false when it is empty.
  bool fill() {
    while (count_ < B_ && pull()) {
    }
    return count_ > 0;
  }
  const Seg& front() const { return window_[head_]; }
  // Squared exit speed of the front block as planned backward from the window's end, where
  // the machine must be able to stop: what the planner knows while that block runs.
  double backward_exit_sqr() const {
    const Seg* w = &window_[head_];
    double v_sqr = 0;
    for (size_t j = count_ - 1; j > 0; --j) v_sqr = std::min(w[j].max_entry_sqr, v_sqr + 2 * w[j].a * w[j].L);
    return v_sqr;
  }
  void pop() {
    head_ = head_ + 1 < cap_ ? head_ + 1 : 0;
    --count_;
  }

 private:
  bool pull() {  // appends the next segment of non-zero length; false at the end
    while (next_ < pts_.size()) {
      const size_t k = next_++;
      const Vec2 d{pts_[k].x - pts_[k - 1].x, pts_[k].y - pts_[k - 1].y};
      const double L = std::hypot(d.x, d.y);
      if (!(L > 1e-9)) continue;  // grbl drops zero-length blocks
      const Vec2 u{d.x / L, d.y / L};
      Seg s{pts_[k - 1], pts_[k], u, L, axis_limited_accel(m_.accel_mm_s2, u), 0, k};
      if (have_prev_) s.max_entry_sqr = std::min(vmax_ * vmax_, junction_speed_sqr(prev_u_, u, m_));
      prev_u_ = u, have_prev_ = true;
      const size_t p = head_ + count_ < cap_ ? head_ + count_ : head_ + count_ - cap_;
      window_[p] = window_[p + cap_] = s;
      ++count_;
      return true;
    }
    return false;
  }

  const std::vector<Vec2>& pts_;
  const double vmax_;
  const MotionParams& m_;
  size_t next_;
  const size_t B_, cap_;
  std::vector<Seg> window_;
  size_t head_ = 0, count_ = 0;
  bool have_prev_ = false;
  Vec2 prev_u_{0, 0};
};

// The direction of the last segment of non-zero length ending before point `end`, if any.
bool direction_before(const std::vector<Vec2>& pts, size_t end, Vec2* u) {
  for (size_t k = end; k-- > 1;) {
    const Vec2 d{pts[k].x - pts[k - 1].x, pts[k].y - pts[k - 1].y};
    const double L = std::hypot(d.x, d.y);
    if (L > 1e-9) {
      *u = {d.x / L, d.y / L};
      return true;
    }
  }
  return false;
}

// polyline_seconds of one long polyline on every thread, the same bit for bit. The only
// thing a block takes from the one before is its entry speed, and its exit speed grows
// with that entry (min(backward, entry^2 + 2aL), each step monotone even as rounded). So
// each piece of ~16,384 points is run twice from the two bounds of its unknown entry, rest
// and the fastest the planner allows; where the two meet (the first corner or window end
// that caps the speed), the true speeds are those from there on, and each block's time is
// known. Only the blocks before that meeting wait for the previous piece's exit speed, in
// a short serial pass; the times are then added in the polyline's order as one pass would.
// O(B * segments) work, O(points) memory (one time a point).
double polyline_seconds_parallel(const std::vector<Vec2>& pts, double vmax, const MotionParams& m) {
  constexpr size_t kPiece = 16384;
  const size_t pieces = (pts.size() - 1 + kPiece - 1) / kPiece;
  std::vector<double> dt(pts.size(), 0.0);  // each block's time at its end point's index
  struct Unsure {
    double L, a, backward_sqr;
    size_t end;
  };
  struct Piece {
    std::vector<Unsure> unsure;  // blocks whose entry waits for the piece before
    bool converged = false;
    double v_exit = 0;  // the last block's exit, when converged
  };
  std::vector<Piece> piece(pieces);
#pragma omp parallel for schedule(dynamic, 1) num_threads(thread_count())
  for (long c = 0; c < static_cast<long>(pieces); ++c) {
    const size_t first = 1 + static_cast<size_t>(c) * kPiece, last = std::min(pts.size(), first + kPiece);
    Vec2 prev_u;
    const bool has_prev = direction_before(pts, first, &prev_u);
    SegmentWindow w(pts, vmax, m, first, has_prev ? &prev_u : nullptr);
    Piece& p = piece[static_cast<size_t>(c)];
    // Before any block of the polyline the pen is at rest: the entry is known.
    p.converged = !has_prev;
    double v = 0, v_lo = 0, v_hi = 0;
    bool started = false;
    while (w.fill() && w.front().end < last) {
      const Seg& s = w.front();
      const double back = w.backward_exit_sqr();
      if (p.converged) {
        const double v_exit = std::sqrt(std::min(back, v * v + 2 * s.a * s.L));
        dt[s.end] = trapezoid_seconds(s.L, v, v_exit, vmax, s.a);
        v = v_exit;
      } else {
        p.unsure.push_back({s.L, s.a, back, s.end});
        v_lo = std::sqrt(std::min(back, (started ? v_lo * v_lo : 0.0) + 2 * s.a * s.L));
        v_hi = started ? std::sqrt(std::min(back, v_hi * v_hi + 2 * s.a * s.L)) : std::sqrt(back);
        started = true;
        if (v_lo == v_hi) p.converged = true, v = v_lo;
      }
      w.pop();
    }
    p.v_exit = v;
  }
  double v = 0;  // the exit speed of the pieces so far
  for (Piece& p : piece) {
    for (const Unsure& u : p.unsure) {
      const double v_exit = std::sqrt(std::min(u.backward_sqr, v * v + 2 * u.a * u.L));
      dt[u.end] = trapezoid_seconds(u.L, v, v_exit, vmax, u.a);
      v = v_exit;
    }
    if (p.converged) v = p.v_exit;  // (equal to the serial pass's v by the bounds above)
  }
  double t = 0;
  for (const double d : dt) t += d;
  return t;
}

constexpr size_t kParallelPolyline = 65536;  // points: below, one pass is quicker than pieces

}  // namespace

double polyline_seconds(const std::vector<Vec2>& pts, double vmax, const MotionParams& m,
                        std::vector<MotionBlock>* out, BlockKind kind, uint32_t layer, double t0) {
  if (!out && pts.size() >= kParallelPolyline && thread_count() > 1 && !in_parallel_part())
    return polyline_seconds_parallel(pts, vmax, m);
  SegmentWindow w(pts, vmax, m, 1, nullptr);
  double t = 0, v_entry = 0;
  while (w.fill()) {
    const Seg& s = w.front();
    const double exit_sqr = std::min(w.backward_exit_sqr(), v_entry * v_entry + 2 * s.a * s.L);  // forward pass
    const double v_exit = std::sqrt(exit_sqr);
    double v_peak = 0;
    const double dt = trapezoid_seconds(s.L, v_entry, v_exit, vmax, s.a, &v_peak);
    if (out) out->push_back({kind, layer, t0 + t, dt, s.from, s.to, v_entry, v_exit, v_peak});
    t += dt;
    v_entry = v_exit;
    w.pop();
  }
  return t;
}

namespace {

// Each stroke's travel to it and its drawing (the pen stops at both ends of each, so
// each time is its own), computed in parallel over runs of strokes of ~8,192 points (the
// runs fixed by the plan alone, the largest first; a tree's outline of 433,000 points is
// timed after them, in pieces on every thread), for the caller to add in plan order: the total is
// the same bit for bit on any thread count. Empty when one thread or a small plan (below
// 100,000 points a thread costs more than it saves). O(points).
struct StrokeSeconds {
  double travel, draw;
};
std::vector<StrokeSeconds> strokes_seconds(const Plan& plan, const MotionParams& m, Vec2 origin) {
  constexpr size_t kRun = 8192, kWorthIt = 100'000;
  if (thread_count() < 2) return {};
  size_t points = 0;
  for (const auto& layer : plan.layers)
    for (const Stroke& s : layer.strokes) points += s.pts.size() + 1;
  if (points < kWorthIt) return {};  // before anything is allocated: the budget times many small plans
  std::vector<const Stroke*> strokes;
  std::vector<Vec2> from;  // where the pen comes from to each stroke
  Vec2 pos = origin;
  for (const auto& layer : plan.layers)
    for (const Stroke& s : layer.strokes) {
      strokes.push_back(&s);
      from.push_back(pos);
      if (!s.pts.empty()) pos = s.pts.back();
    }
  std::vector<std::pair<size_t, size_t>> runs;  // [first, last) strokes
  std::vector<size_t> run_points;
  for (size_t i = 0, in_run = 0; i < strokes.size(); ++i) {
    if (in_run == 0) runs.push_back({i, i}), run_points.push_back(0);
    runs.back().second = i + 1;
    in_run += strokes[i]->pts.size() + 1;
    run_points.back() = in_run;
    if (in_run >= kRun) in_run = 0;
  }
  std::vector<size_t> order(runs.size());
  for (size_t r = 0; r < order.size(); ++r) order[r] = r;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return run_points[a] > run_points[b]; });
  std::vector<StrokeSeconds> out(strokes.size(), StrokeSeconds{0, 0});
#pragma omp parallel num_threads(thread_count())
  {
    std::vector<Vec2> travel(2);
#pragma omp for schedule(dynamic, 1)
    for (long k = 0; k < static_cast<long>(order.size()); ++k) {
      const auto [first, last] = runs[order[static_cast<size_t>(k)]];
      for (size_t i = first; i < last; ++i) {
        const Stroke& s = *strokes[i];
        if (s.pts.empty()) continue;
        travel[0] = from[i];
        travel[1] = s.pts.front();
        // A very long stroke is timed below, in pieces on every thread.
        const bool long_stroke = s.pts.size() >= kParallelPolyline;
        out[i] = {polyline_seconds(travel, m.speed_up_mm_s, m), long_stroke ? 0.0 : polyline_seconds(s.pts, m.speed_down_mm_s, m)};
      }
    }
  }
  for (size_t i = 0; i < strokes.size(); ++i)
    if (strokes[i]->pts.size() >= kParallelPolyline) out[i].draw = polyline_seconds(strokes[i]->pts, m.speed_down_mm_s, m);
  return out;
}

}  // namespace

MotionTimeline simulate_motion(const Plan& plan, const MotionParams& m, Vec2 origin, bool return_home,
                               bool keep_blocks) {
  validate(m);
  MotionTimeline tl;
  std::vector<MotionBlock>* out = keep_blocks ? &tl.blocks : nullptr;
  // Blocks are kept in time order, so only a plain timing takes the strokes apart.
  const std::vector<StrokeSeconds> apart = out ? std::vector<StrokeSeconds>{} : strokes_seconds(plan, m, origin);
  size_t k = 0;  // the stroke's number in the plan
  Vec2 pos = origin;
  double t = 0;
  std::vector<Vec2> travel(2);
  for (uint32_t li = 0; li < plan.layers.size(); ++li) {
    const double layer_t0 = t;
    t += m.pen_change_s;  // take up this layer's pen
    for (const Stroke& s : plan.layers[li].strokes) {
      const StrokeSeconds* timed = k < apart.size() ? &apart[k] : nullptr;
      ++k;
      if (s.pts.empty()) continue;
      travel[0] = pos;
      travel[1] = s.pts.front();
      t += timed ? timed->travel : polyline_seconds(travel, m.speed_up_mm_s, m, out, BlockKind::Travel, li, t);
      if (out) out->push_back({BlockKind::PenDown, li, t, m.pen_drop_s, s.pts.front(), s.pts.front()});
      t += m.pen_drop_s;
      t += timed ? timed->draw : polyline_seconds(s.pts, m.speed_down_mm_s, m, out, BlockKind::Draw, li, t);
      if (out) out->push_back({BlockKind::PenUp, li, t, m.pen_lift_s, s.pts.back(), s.pts.back()});
      t += m.pen_lift_s;
      pos = s.pts.back();
    }
    tl.layer_seconds.push_back(t - layer_t0);
  }
  if (!plan.layers.empty()) t += m.pen_change_s;  // put the last pen away
  if (return_home) {
    travel[0] = pos;
    travel[1] = origin;
    tl.home_seconds = polyline_seconds(travel, m.speed_up_mm_s, m, out, BlockKind::Travel,
                                       plan.layers.empty() ? 0 : static_cast<uint32_t>(plan.layers.size() - 1), t);
    t += tl.home_seconds;
  }
  tl.total_seconds = t;
  return tl;
}

double estimate_seconds(const Plan& plan, const MotionParams& m) { return simulate_motion(plan, m).total_seconds; }

}  // namespace stipplot::motion
