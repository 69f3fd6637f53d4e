#include "drivers/stream/ebb/reset.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "drivers/job/ebb_reader.hpp"
#include "drivers/motion/ebb_motion.hpp"

namespace stipplot::io::ebb {

namespace {

// A motor may stand this far (steps) from the straight line of its move: its step
// comes when its rate accumulator overflows, up to a tick after the other motor's.
constexpr double kPathTol = 1.5;

double length_mm(const Steps& a, const Steps& b, double spm) {
  const double d1 = static_cast<double>(b[0] - a[0]), d2 = static_cast<double>(b[1] - a[1]);
  return std::hypot((d1 + d2) / 2, (d1 - d2) / 2) / spm;
}

}  // namespace

Steps steps_after(const Job& job, long i, double spm) {
  if (i < 0) return {0, 0};
  const JobLine& l = job.lines[static_cast<size_t>(i)];
  return ebb_motor_steps(l.x, l.y, spm);
}

SmPart sm_remainder(int64_t ms, int64_t s1, int64_t s2, const Steps& done) {
  SmPart r{0, s1 - done[0], s2 - done[1]};
  // The larger motor says how far along the move is (the other may lag it by a step).
  const bool first = std::llabs(s1) >= std::llabs(s2);
  const double whole = static_cast<double>(std::llabs(first ? s1 : s2));
  const double left = static_cast<double>(first ? r.s1 : r.s2) * ((first ? s1 : s2) < 0 ? -1 : 1);
  const double share = whole > 0 ? std::clamp(left / whole, 0.0, 1.0) : 1.0;
  const int64_t fastest = (std::max(std::llabs(r.s1), std::llabs(r.s2)) + motion::kEbbStepsPerMs - 1) / motion::kEbbStepsPerMs;
  r.ms = std::max<int64_t>({1, std::llround(static_cast<double>(ms) * share), fastest});
  return r;
}

bool on_sm_path(const Job& job, size_t i, const Steps& at, double spm) {
  if (i >= job.lines.size() || !job.lines[i].motion) return false;
  const Steps p0 = steps_after(job, static_cast<long>(i) - 1, spm), p1 = steps_after(job, static_cast<long>(i), spm);
  double lo = 0, hi = 1;  // the time shares at which both motors can stand where `at` says
  for (int k = 0; k < 2; ++k) {
    const double s = static_cast<double>(p1[k] - p0[k]), q = static_cast<double>(at[k] - p0[k]);
    if (s == 0) {
      if (std::fabs(q) > kPathTol) return false;
      continue;
    }
    double a = (q - kPathTol) / s, b = (q + kPathTol) / s;
    if (a > b) std::swap(a, b);
    lo = std::max(lo, a);
    hi = std::min(hi, b);
  }
  return lo <= hi;
}

long first_on_path(const Job& job, size_t from, size_t to, const Steps& at, double spm) {
  for (size_t i = from; i <= to && i < job.lines.size(); ++i)
    if (on_sm_path(job, i, at, spm)) return static_cast<long>(i);
  return -1;
}

size_t first_unsure(const Job& job, long last, int fifo) {
  int queued = 0;
  for (long i = std::min<long>(last, static_cast<long>(job.lines.size()) - 1); i >= 0; --i) {
    const JobLine& l = job.lines[static_cast<size_t>(i)];
    if (l.host_only) continue;
    const std::string n = ebb_command_name(l.text);
    if ((ebb_motion_command(n) || n == "SP" || n == "EM") && ++queued == fifo + 1) return static_cast<size_t>(i);
  }
  return 0;
}

ResumePlan plan_reset_resume(const Job& job, const JournalState& journal, const DeviceProfile& profile, int fifo) {
  const auto& L = job.lines;
  const double spm = profile.ebb.steps_per_mm;
  const long last = std::min(journal.last_acked, static_cast<long>(L.size()) - 1);
  size_t first_sm = 0;
  while (first_sm < L.size() && (L[first_sm].host_only || !ebb_motion_command(ebb_command_name(L[first_sm].text)))) ++first_sm;
  const size_t lo = first_unsure(job, last, fifo);

  // The last proof, when it says more than the FIFO's bound does.
  size_t from = lo;
  bool split = false, proved = false;
  Steps at{0, 0};
  std::string why_not;
  const ProvenPoint& p = journal.proven;
  if (p.line < 0) {
    why_not = "the journal holds no proof";
  } else if (p.line > last) {
    why_not = "the last proof (line " + std::to_string(p.line + 1) + ") is past the acknowledged lines";
  } else {
    const size_t i = static_cast<size_t>(p.line);
    const Steps q = ebb_motor_steps(p.x, p.y, spm);
    const Steps p0 = steps_after(job, p.line - 1, spm), p1 = steps_after(job, p.line, spm);
    if (!on_sm_path(job, i, q, spm)) {
      why_not = "the last proof does not lie on line " + std::to_string(i + 1) + "'s path";
    } else if (i < lo) {
      why_not = "the last proof is earlier";
    } else {
      proved = true;
      if (q == p1) {
        from = i + 1;  // at its end: the line ran
      } else if (q == p0 || !L[i].pen_down) {
        from = q == p0 ? i : i + 1;  // a travel's rest is the preamble's own travel
      } else {
        split = true;
        from = i;
        at = q;
      }
    }
  }

  // Lines that neither move nor leave the pen down (its lift, a pause the journal counted
  // as done) ran if they were acknowledged: a pause is not asked again.
  while (!split && from > first_sm && static_cast<long>(from) <= last && !L[from].motion && !L[from].pen_down) ++from;
  ResumePlan rp;
  if (from <= first_sm) {  // nothing drawn yet that counts: the job from its start (EM zeroes the board)
    rp.next = 0;
    rp.why = proved ? "from the start: the last proof is before the first move" : "from the start: the board may have run none of its moves";
    return rp;
  }
  // The job's own set-up (EM, SC, its pen-up), then the pen up in any case.
  std::string pen_up, pen_down;
  for (size_t k = 0; k < L.size() && pen_up.empty(); ++k)
    if (!L[k].host_only && ebb_command_name(L[k].text) == "SP" && parse_ebb_command(L[k].text, k + 1).pen == 1) pen_up = L[k].text;
  bool header_lifts = false;
  for (size_t k = 0; k < first_sm; ++k) {
    if (L[k].host_only) continue;
    rp.preamble.push_back(L[k].text);
    if (ebb_command_name(L[k].text) == "SP") header_lifts = !L[k].pen_down;
  }
  if (!header_lifts && !pen_up.empty()) rp.preamble.push_back(pen_up);
  // An accelerated travel from home, as the writer moves (a constant-speed jump would stall
  // a real stepper), in the job's own kind of moves: LMs if it has any (its firmware runs
  // them), else SMs.
  const Steps target = split ? at : steps_after(job, static_cast<long>(from) - 1, spm);
  const motion::EbbGeometry geo{spm};
  const bool lm = std::any_of(L.begin(), L.end(), [](const JobLine& l) { return !l.host_only && ebb_command_name(l.text) == "LM"; });
  const motion::EbbMoveSettings how{lm ? motion::EbbMoveKind::lm : motion::EbbMoveKind::sm, profile.ebb.time_slice_ms};
  motion::MotorSteps pos{0, 0};
  int64_t clock_ticks = 0;
  std::vector<motion::MotionBlock> blocks;
  std::vector<motion::EbbMove> moves;
  // From rest at `pos` to rest at `to` (motor steps), to the step. O(moves).
  auto move_to = [&](const Steps& to, double speed) {
    moves.clear();
    motion::polyline_moves({geo.mm(pos), geo.mm({to[0], to[1]})}, speed, profile.motion, geo, how, pos, clock_ticks, blocks,
                           moves);
    for (const motion::EbbMove& m : moves) rp.preamble.push_back(motion::ebb_command(m));
    if (pos[0] != to[0] || pos[1] != to[1]) {  // rounding never leaves it off, but to the step it must be
      const SmPart fix = sm_remainder(1, to[0] - pos[0], to[1] - pos[1], {0, 0});
      rp.preamble.push_back(motion::sm_command({fix.ms, fix.s1, fix.s2}));
      pos = to;
    }
  };
  move_to(target, profile.motion.speed_up_mm_s);
  const bool down = split || L[from - 1].pen_down;
  if (down) {
    for (size_t k = from; k-- > 0;)
      if (!L[k].host_only && ebb_command_name(L[k].text) == "SP" && L[k].pen_down) {
        rp.preamble.push_back(L[k].text);  // the job's own pen-down, with its delay
        break;
      }
  }
  double redraw = 0;
  if (split) {
    const EbbCommand c = parse_ebb_command(L[from].text, from + 1);
    const Steps p0 = steps_after(job, static_cast<long>(from) - 1, spm);
    if (c.name == "LM") {
      // An LM's ramp cannot be cut where it stood: its rest, from rest, planned again
      // to its end at the pen-down speed.
      move_to(steps_after(job, static_cast<long>(from), spm), profile.motion.speed_down_mm_s);
    } else {
      const SmPart r = sm_remainder(c.ms, c.s1, c.s2, {at[0] - p0[0], at[1] - p0[1]});
      rp.preamble.push_back(motion::sm_command({r.ms, r.s1, r.s2}));
    }
    redraw += length_mm(at, steps_after(job, static_cast<long>(from), spm), spm);
    rp.next = from + 1;
  } else {
    rp.next = from;
  }
  for (long k = static_cast<long>(rp.next); k <= last; ++k)
    if (L[static_cast<size_t>(k)].motion && L[static_cast<size_t>(k)].pen_down)
      redraw += length_mm(steps_after(job, k - 1, spm), steps_after(job, k, spm), spm);
  rp.redraw = redraw;
  char b[200];
  if (proved)
    std::snprintf(b, sizeof b, "from the last point proved drawn before the reset (QS on line %ld%s)", p.line + 1,
                  !split ? "" : ebb_command_name(L[from].text) == "LM" ? ", its LM's rest split there and planned again" : ", its SM split there");
  else
    std::snprintf(b, sizeof b, "from the first line the board may not have run (its FIFO of %d commands was lost; %s)", fifo,
                  why_not.c_str());
  rp.why = b;
  return rp;
}

}  // namespace stipplot::io::ebb
