#include "drivers/motion/ebb_motion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace stipplot::motion {

MotorSteps EbbGeometry::steps(Vec2 p) const {
  return {std::llround(steps_per_mm * (p.x + p.y)), std::llround(steps_per_mm * (p.x - p.y))};
}

Vec2 EbbGeometry::mm(const MotorSteps& s) const {
  return {static_cast<double>(s[0] + s[1]) / (2 * steps_per_mm), static_cast<double>(s[0] - s[1]) / (2 * steps_per_mm)};
}

bool ebb_move_ok(const EbbMove& m) {
  return m.ms >= 1 && std::llabs(m.s1) <= kEbbStepsPerMs * m.ms && std::llabs(m.s2) <= kEbbStepsPerMs * m.ms;
}

std::string sm_command(const EbbMove& m) {
  char b[80];
  std::snprintf(b, sizeof b, "SM,%lld,%lld,%lld", static_cast<long long>(m.ms), static_cast<long long>(m.s1),
                static_cast<long long>(m.s2));
  return b;
}

namespace {

__extension__ typedef __int128 Wide;  // an LM's accumulator sums pass 2^63 (ticks^2 * accel)

// A block becomes one LM ramp when its ends' speeds jump by at most this share of its
// peak speed (or what its acceleration gives in a millisecond) for it.
constexpr double kOneRampJump = 0.05;

// What one motor of a cleared LM has accumulated after n ticks. O(1).
Wide lm_accumulated(int64_t r, int64_t a, int64_t n) {
  return static_cast<Wide>(n) * (r - a / 2) + static_cast<Wide>(a) * n * (n + 1) / 2;
}

bool in_int32(int64_t v) { return v >= -(kEbbOneStep - 1) && v <= kEbbOneStep - 1; }

// One motor's LM terms for `steps` (> 0) in n ticks, its rate from share w0 to w1 of the
// average: the shape's accel, then the least rate whose accumulator holds every step by
// tick n (never less than 0). O(1).
void lm_motor_terms(int64_t steps, int64_t n, double w0, double w1, int64_t& r, int64_t& a) {
  r = a = 0;
  if (steps == 0) return;
  const double mean = static_cast<double>(steps) * static_cast<double>(kEbbOneStep) / static_cast<double>(n);
  a = std::llround(mean * (w1 - w0) / static_cast<double>(n));
  const Wide need = static_cast<Wide>(steps) * kEbbOneStep - static_cast<Wide>(a) * n * (n + 1) / 2;
  Wide re = need / n;
  if (re * n < need) ++re;  // the ceiling: the last step by tick n
  r = std::max<int64_t>(0, static_cast<int64_t>(re) + a / 2);
}

}  // namespace

int64_t lm_rate(int64_t r, int64_t a, int64_t n) { return r - a / 2 + n * a; }

int64_t lm_motor_ticks(int64_t steps, int64_t r, int64_t a) {
  if (steps <= 0) return 0;
  const int64_t first = lm_rate(r, a, 1);
  if (first <= 0) return -1;
  const Wide goal = static_cast<Wide>(steps) * kEbbOneStep;
  // The accumulator rises while the rate is positive: up to tick hi at most.
  int64_t hi;
  if (a < 0) {
    hi = (r - a / 2 - 1) / -a;  // the last tick with a rate of 1 or more
    if (hi < 1 || lm_accumulated(r, a, hi) < goal) return -1;
  } else {
    hi = static_cast<int64_t>((goal + first - 1) / first);  // at the first tick's rate, the slowest
    // ... and by the accel alone (acc >= a n^2 / 2), which keeps n^2 * a within 128 bits.
    if (a > 0) hi = std::min(hi, static_cast<int64_t>(std::sqrt(2 * static_cast<double>(goal) / static_cast<double>(a))) + 2);
    while (lm_accumulated(r, a, hi) < goal) hi *= 2;  // a negative r: the bound is the accel's alone
  }
  int64_t lo = 1;  // binary search for the first tick that holds every step: O(log ticks)
  while (lo < hi) {
    const int64_t mid = lo + (hi - lo) / 2;
    if (lm_accumulated(r, a, mid) >= goal) hi = mid;
    else lo = mid + 1;
  }
  return lo;
}

int64_t lm_ticks(const EbbMove& m) {
  const int64_t t1 = lm_motor_ticks(std::llabs(m.s1), m.r1, m.a1), t2 = lm_motor_ticks(std::llabs(m.s2), m.r2, m.a2);
  return t1 < 0 || t2 < 0 ? -1 : std::max(t1, t2);
}

bool lm_ok(const EbbMove& m) {
  if (!m.lm || (m.s1 == 0 && m.s2 == 0)) return false;
  const std::array<std::array<int64_t, 3>, 2> motors{{{m.s1, m.r1, m.a1}, {m.s2, m.r2, m.a2}}};
  for (const auto& [s, r, a] : motors) {
    if (!in_int32(s) || !in_int32(r) || !in_int32(a) || r < 0) return false;
    if (s == 0) continue;
    const int64_t n = lm_motor_ticks(std::llabs(s), r, a);
    if (n < 1) return false;
    // The rate is linear in the tick: within the firmware's one step a tick at both ends.
    if (lm_rate(r, a, 1) >= kEbbOneStep || lm_rate(r, a, n) >= kEbbOneStep) return false;
  }
  return true;
}

std::string ebb_command(const EbbMove& m) {
  if (!m.lm) return sm_command(m);
  char b[160];
  std::snprintf(b, sizeof b, "LM,%lld,%lld,%lld,%lld,%lld,%lld,3", static_cast<long long>(m.r1),
                static_cast<long long>(m.s1), static_cast<long long>(m.a1), static_cast<long long>(m.r2),
                static_cast<long long>(m.s2), static_cast<long long>(m.a2));
  return b;
}

std::optional<EbbMove> lm_phase(int64_t s1, int64_t s2, int64_t ticks, double v0, double v1) {
  const int64_t most = std::max(std::llabs(s1), std::llabs(s2));
  if (most == 0 || !(v0 >= 0 && v1 >= 0 && v0 + v1 > 0)) return std::nullopt;
  const double w0 = 2 * v0 / (v0 + v1), w1 = 2 * v1 / (v0 + v1);
  // At most one step a tick, at the phase's faster end.
  int64_t n = std::max<int64_t>({ticks, 1, static_cast<int64_t>(std::ceil(std::max(w0, w1) * static_cast<double>(most) * 1.001)) + 1});
  for (int attempt = 0; attempt < 8; ++attempt, n += std::max<int64_t>(1, n / 16)) {
    EbbMove m;
    m.lm = true;
    m.s1 = s1, m.s2 = s2;
    lm_motor_terms(std::llabs(s1), n, w0, w1, m.r1, m.a1);
    lm_motor_terms(std::llabs(s2), n, w0, w1, m.r2, m.a2);
    if (lm_ok(m)) return m;
  }
  return std::nullopt;
}

double block_distance(const MotionBlock& b, double a, double t) {
  const double L = std::hypot(b.to.x - b.from.x, b.to.y - b.from.y);
  const double v0 = b.v_entry, v1 = b.v_exit, vp = std::max({b.v_peak, v0, v1});
  const double t1 = a > 0 ? (vp - v0) / a : 0, t3 = a > 0 ? (vp - v1) / a : 0;
  const double d1 = (v0 + vp) / 2 * t1, d3 = (vp + v1) / 2 * t3;
  const double t2 = vp > 0 ? std::max(0.0, (L - d1 - d3) / vp) : 0;
  double d;
  if (t <= t1) {
    d = v0 * t + a * t * t / 2;
  } else if (t <= t1 + t2) {
    d = d1 + vp * (t - t1);
  } else {
    const double u = std::min(t - t1 - t2, t3);
    d = d1 + vp * t2 + vp * u - a * u * u / 2;
  }
  return std::clamp(d, 0.0, L);
}

void slice_blocks(const std::vector<MotionBlock>& blocks, const EbbGeometry& g, double accel_mm_s2, int slice_ms, MotorSteps& at,
                  int64_t& clock_ms, std::vector<EbbMove>& out) {
  if (blocks.empty()) return;
  // The chain's continuous time starts at the clock; block i starts at t0 + its offset.
  const double t0 = static_cast<double>(clock_ms) / 1000 - blocks.front().start_s;
  for (const MotionBlock& b : blocks) {
    const Vec2 d{b.to.x - b.from.x, b.to.y - b.from.y};
    const double L = std::hypot(d.x, d.y);
    if (!(L > 0)) continue;
    const Vec2 u{d.x / L, d.y / L};
    // The block's acceleration as polyline_seconds took it (grbl's per-axis limit).
    const double T = b.duration_s;
    const int n = std::max(1, static_cast<int>(std::ceil(T * 1000 / slice_ms - 1e-9)));
    const double a = axis_limited_accel(accel_mm_s2, u);
    for (int i = 1; i <= n; ++i) {
      const double t = T * i / n;
      const Vec2 p = i == n ? b.to : Vec2{b.from.x + u.x * block_distance(b, a, t), b.from.y + u.y * block_distance(b, a, t)};
      const MotorSteps s = g.steps(p);
      EbbMove m{std::max<int64_t>(1, std::llround((t0 + b.start_s + t) * 1000) - clock_ms), s[0] - at[0], s[1] - at[1]};
      // Faster than the interrupt can step (a sample pushed late, rounding): stretch it.
      const int64_t need = (std::max(std::llabs(m.s1), std::llabs(m.s2)) + kEbbStepsPerMs - 1) / kEbbStepsPerMs;
      m.ms = std::max(m.ms, need);
      out.push_back(m);
      clock_ms += m.ms;
      at = s;
    }
  }
}

void lm_blocks(const std::vector<MotionBlock>& blocks, const EbbGeometry& g, double accel_mm_s2, MotorSteps& at,
               int64_t& clock_ticks, std::vector<EbbMove>& out) {
  if (blocks.empty()) return;
  const double tps = static_cast<double>(kEbbTicksPerS);
  const double t0 = static_cast<double>(clock_ticks) / tps - blocks.front().start_s;
  for (const MotionBlock& b : blocks) {
    const Vec2 d{b.to.x - b.from.x, b.to.y - b.from.y};
    const double L = std::hypot(d.x, d.y);
    if (!(L > 0)) continue;
    const Vec2 u{d.x / L, d.y / L};
    const double a = axis_limited_accel(accel_mm_s2, u);
    const double T = b.duration_s, v0 = b.v_entry, v1 = b.v_exit, vp = std::max({b.v_peak, v0, v1});
    const double t1 = a > 0 ? std::min(T, (vp - v0) / a) : 0;
    const double t3 = a > 0 ? std::min(T - t1, (vp - v1) / a) : 0;
    struct Phase {
      double end_s, v_start, v_end;
    };
    std::array<Phase, 3> phases{{{t1, v0, vp}, {T - t3, vp, vp}, {T, vp, v1}}};
    size_t count = phases.size();
    // A block one ramp from entry to exit speed follows closely (a short one between
    // corners of nearly its cruise speed, as in a spiral of short segments) is one LM: its
    // mean speed scales the ramp by k, so the speeds at its ends jump by |k - 1| of theirs.
    const double ramp_mean = (v0 + v1) / 2;
    if (T > 0 && ramp_mean > 0) {
      const double jump = std::fabs(L / T / ramp_mean - 1) * std::max(v0, v1);
      if (jump <= std::max(kOneRampJump * vp, a * 0.001)) phases[0] = {T, v0, v1}, count = 1;
    }
    double start = 0;
    for (size_t k = 0; k < count; ++k) {
      const Phase& ph = phases[k];
      if (k + 1 < count && !(ph.end_s > start)) continue;  // no such phase (a triangle, no ramp)
      start = ph.end_s;
      const double s = k + 1 < count ? block_distance(b, a, ph.end_s) : L;
      const MotorSteps target = k + 1 < count ? g.steps({b.from.x + u.x * s, b.from.y + u.y * s}) : g.steps(b.to);
      const int64_t s1 = target[0] - at[0], s2 = target[1] - at[1];
      if (s1 == 0 && s2 == 0) continue;  // less than a step: its time goes to the next phase
      const int64_t ticks = std::llround((t0 + b.start_s + ph.end_s) * tps) - clock_ticks;
      if (const auto lm = lm_phase(s1, s2, ticks, ph.v_start, ph.v_end)) {
        out.push_back(*lm);
        clock_ticks += lm_ticks(*lm);
      } else {  // no LM fits: an SM of the phase's time, within 25 steps a ms
        EbbMove sm{std::max<int64_t>(1, (ticks + 24) / 25), s1, s2};
        sm.ms = std::max<int64_t>(sm.ms, (std::max(std::llabs(s1), std::llabs(s2)) + kEbbStepsPerMs - 1) / kEbbStepsPerMs);
        out.push_back(sm);
        clock_ticks += sm.ms * 25;
      }
      at = target;
    }
  }
}

void polyline_moves(const std::vector<Vec2>& pts, double vmax, const MotionParams& m, const EbbGeometry& g,
                    const EbbMoveSettings& how, MotorSteps& at, int64_t& clock_ticks, std::vector<MotionBlock>& blocks,
                    std::vector<EbbMove>& out) {
  if (pts.size() < 2) return;
  blocks.clear();
  polyline_seconds(pts, vmax, m, &blocks);
  if (how.kind == EbbMoveKind::lm) {
    lm_blocks(blocks, g, m.accel_mm_s2, at, clock_ticks, out);
    return;
  }
  int64_t clock_ms = (clock_ticks + 24) / 25;  // SMs last whole milliseconds
  slice_blocks(blocks, g, m.accel_mm_s2, how.slice_ms, at, clock_ms, out);
  clock_ticks = clock_ms * 25;
}

}  // namespace stipplot::motion
