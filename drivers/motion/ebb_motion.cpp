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

void polyline_moves(const std::vector<Vec2>& pts, double vmax, const MotionParams& m, const EbbGeometry& g, int slice_ms,
                    MotorSteps& at, int64_t& clock_ms, std::vector<MotionBlock>& blocks, std::vector<EbbMove>& out) {
  if (pts.size() < 2) return;
  blocks.clear();
  polyline_seconds(pts, vmax, m, &blocks);
  slice_blocks(blocks, g, m.accel_mm_s2, slice_ms, at, clock_ms, out);
}

}  // namespace stipplot::motion
