#include "improve.hpp"

#include <algorithm>
#include <cmath>

#include "util/rng.hpp"

namespace stipplot::plan::tour {

namespace {
// Gains below this are rounding, not improvement: every applied move shortens the path
// by more, so the search cannot cycle.
constexpr double kEps = 1e-9;
// Kicks swap two neighbouring stretches of the path of up to this many nodes each: a
// double bridge whose new edges stay local, done in O(length) on the array.
constexpr uint32_t kMaxKickSegment = 50;
// The local search's reversal caps before its uncapped stage.
constexpr uint32_t kStageReversals[2] = {1000, 30000};
// After a kick, moves that would reverse more than this are not taken: a kick's repair
// stays O(1) work on huge paths, at a small cost in what kicks find.
constexpr uint32_t kKickReversals = 10000;
// Passes of the local search over every node stop when one finds fewer moves than one
// per this many nodes, or after kMaxPasses.
constexpr long kPassYield = 500;
constexpr int kMaxPasses = 20;
// Perturbation trials come in kRounds rounds (of at least kMinRound); one that saves less
// than kRoundYield of the pen-up travel ends them.
constexpr long kRounds = 20, kMinRound = 1000;
constexpr double kRoundYield = 1e-4;
}  // namespace

PathImprover::PathImprover(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                           const std::vector<uint32_t>& order, const Candidates& cand)
    : n_(static_cast<uint32_t>(pts.size())), N_(n_ + 2), O_(n_), D_(n_ + 1), cand_(cand) {
  p_.reserve(N_);
  p_ = pts;
  p_.push_back(start);
  p_.push_back(start);
  partner_.reserve(N_);
  partner_ = partner;
  partner_.push_back(static_cast<int32_t>(D_));
  partner_.push_back(static_cast<int32_t>(O_));
  tour_.reserve(N_);
  tour_.push_back(O_);
  tour_.insert(tour_.end(), order.begin(), order.end());
  tour_.push_back(D_);
  pos_.resize(N_);
  for (uint32_t i = 0; i < N_; ++i) pos_[tour_[i]] = i;
  queue_.resize(N_);
  queued_.assign(N_, 0);
}

std::vector<uint32_t> PathImprover::path() const {
  // Read the cycle from O in the direction away from D.
  std::vector<uint32_t> out;
  out.reserve(n_);
  const bool fwd = next(O_) != D_;
  for (uint32_t v = succ(O_, fwd); v != D_; v = succ(v, fwd)) out.push_back(v);
  return out;
}

template <class F>
void PathImprover::for_candidates(uint32_t a, F&& f) const {
  if (a == D_) return;
  if (a < n_ && !f(D_)) return;  // ending the path at a costs nothing
  const uint32_t* row = cand_.row(a);  // row n_ is the start's: O's
  for (uint32_t s = 0; s < cand_.k && row[s] != kNoNode; ++s)
    if (!f(row[s])) return;
}

void PathImprover::push(uint32_t v) {
  if (queued_[v]) return;
  queued_[v] = 1;
  queue_[(head_ + count_) % N_] = v;
  ++count_;
}

void PathImprover::reverse_positions(uint32_t i, uint32_t len) {
  if (logging_) log_.emplace_back(i, len);
  reversed_ += len;
  if (i + static_cast<uint64_t>(len) <= N_) {
    // Contiguous: a plain reverse, then the positions of what moved (the common case,
    // and twice as fast as swapping with the wrap-around checks).
    uint32_t* t = tour_.data();
    std::reverse(t + i, t + i + len);
    for (uint32_t k = i; k < i + len; ++k) pos_[t[k]] = k;
    return;
  }
  uint32_t j = static_cast<uint32_t>((static_cast<uint64_t>(i) + len + N_ - 1) % N_);
  for (uint32_t s = 0; s < len / 2; ++s) {
    std::swap(tour_[i], tour_[j]);
    pos_[tour_[i]] = i;
    pos_[tour_[j]] = j;
    i = i + 1 == N_ ? 0 : i + 1;
    j = j == 0 ? N_ - 1 : j - 1;
  }
}

// Removes edges (a,b), (c,d) and adds (a,c), (b,d); a, b, ..., c, d must follow each
// other in one direction round the cycle. Reverses whichever side is shorter.
void PathImprover::move(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  if (next(a) != b) {  // the mirror image: d, c, ..., b, a forward
    std::swap(a, d);
    std::swap(b, c);
  }
  uint32_t i = pos_[b];
  uint32_t len = (pos_[c] + N_ - i) % N_ + 1;
  if (2 * static_cast<uint64_t>(len) > N_) {
    i = pos_[d];
    len = N_ - len;
  }
  reverse_positions(i, len);
  touched_.insert(touched_.end(), {a, b, c, d});
}

double PathImprover::try_2opt(uint32_t a) {
  for (const bool fwd : {true, false}) {
    const uint32_t b = succ(a, fwd);
    if (fixed(a, b)) continue;
    const double dab = dist(a, b);
    double gain = 0;
    uint32_t c_best = kNoNode, d_best = kNoNode;
    for_candidates(a, [&](uint32_t c) {
      const double g1 = dab - dist(a, c);
      if (g1 <= kEps) return false;  // candidates come nearest first: none further can gain
      const uint32_t d = succ(c, fwd);
      if (c == b || d == a || fixed(c, d)) return true;
      const double g = g1 + dist(c, d) - dist(b, d);
      if (g <= kEps) return true;
      if (reversal_length(b, c) > max_reversal_) {
        capped_out_ = true;
        return true;
      }
      gain = g, c_best = c, d_best = d;
      return false;
    });
    if (c_best != kNoNode) {
      move(a, b, c_best, d_best);
      return gain;
    }
  }
  return 0;
}

double PathImprover::try_oropt(uint32_t a) {
  const double g = try_oropt_from(a, true);
  return g > 0 ? g : try_oropt_from(a, false);
}

// Moves the segment starting at s1 (1 to 3 units in direction fwd, a stroke being one
// unit) between two adjacent nodes x, y near either of its ends, in the better
// orientation: p S nx .. x y  ->  p nx .. x S y.
double PathImprover::try_oropt_from(uint32_t s1, bool fwd) {
  if (s1 == O_ || s1 == D_) return 0;
  const uint32_t p = succ(s1, !fwd);
  if (fixed(p, s1)) return 0;
  uint32_t seg[6];
  uint32_t len = 0, s2 = s1;
  auto take = [&](uint32_t v) {
    if (v == O_ || v == D_ || v == p) return false;
    seg[len++] = v;
    s2 = v;
    return true;
  };
  take(s1);
  for (int units = 1; units <= 3; ++units) {
    if (units > 1 && !take(succ(s2, fwd))) return 0;
    if (fixed(s2, succ(s2, fwd)) && !take(succ(s2, fwd))) return 0;
    // Backwards, a single node is the segment already tried forwards.
    if (!fwd && len == 1) continue;
    if (len + 4 > N_) return 0;
    const uint32_t nx = succ(s2, fwd);
    const double removed = dist(p, s1) + dist(s2, nx) - dist(p, nx);
    if (removed <= kEps) continue;
    auto in_seg = [&](uint32_t v) { return std::find(seg, seg + len, v) != seg + len; };
    double best = kEps;
    uint32_t bx = kNoNode, by = kNoNode;
    bool brev = false;
    for (const uint32_t e : {s1, s2}) {
      if (e == s2 && s2 == s1) break;
      for_candidates(e, [&](uint32_t c) {
        if (dist(e, c) >= removed) return false;
        if (in_seg(c)) return true;
        for (const bool after : {true, false}) {  // insert between c and its successor, or its predecessor and c
          const uint32_t x = after ? c : succ(c, !fwd), y = after ? succ(c, fwd) : c;
          if (in_seg(x) || in_seg(y) || fixed(x, y)) continue;
          const double base = removed + dist(x, y);
          const double g_keep = base - dist(x, s1) - dist(s2, y);
          const double g_flip = base - dist(x, s2) - dist(s1, y);
          if (std::max(g_keep, g_flip) <= best) continue;
          if (reversal_length(s1, x) > max_reversal_) {
            capped_out_ = true;
            continue;
          }
          if (g_keep > best) best = g_keep, bx = x, by = y, brev = false;
          if (g_flip > best) best = g_flip, bx = x, by = y, brev = true;
        }
        return true;
      });
    }
    if (bx != kNoNode) {
      // Three reversals: p S nx..x y -> p x..nx S^r y -> p nx..x S^r y [-> p nx..x S y].
      move(p, s1, bx, by);
      move(p, bx, nx, s2);
      if (!brev) move(bx, s2, s1, by);
      return best;
    }
  }
  return 0;
}

double PathImprover::drain_queue(Clock::time_point cap, ImproveStats& st) {
  double total = 0;
  while (count_ > 0) {
    if ((++check_ & 255) == 0 && Clock::now() > cap) {
      st.capped = true;
      break;
    }
    const uint32_t a = queue_[head_];
    head_ = head_ + 1 == N_ ? 0 : head_ + 1;
    --count_;
    queued_[a] = 0;
    touched_.clear();
    capped_out_ = false;
    double g = try_2opt(a);
    if (g > 0) {
      ++st.moves_2opt;
    } else if ((g = try_oropt(a)) > 0) {
      ++st.moves_oropt;
    } else {
      if (capped_out_) deferred_.push_back(a);
      continue;
    }
    total += g;
    push(a);
    for (const uint32_t t : touched_) push(t);
  }
  return total;
}

void PathImprover::local_search(Clock::time_point cap, ImproveStats& st) {
  // In stages of growing reversal caps: the cheap local fixes first, so the long moves
  // left for the last, uncapped stage are fewer (a third of the reversal work at 1M
  // nodes, and a slightly better optimum). A stage re-examines only the nodes whose best
  // move the previous one's cap refused.
  double gain = 0;
  for (const uint32_t v : tour_) push(v);
  for (const uint32_t limit : kStageReversals) {
    if (2 * static_cast<uint64_t>(limit) >= N_) break;
    max_reversal_ = limit;
    gain += drain_queue(cap, st);
    for (const uint32_t v : deferred_) push(v);
    deferred_.clear();
  }
  max_reversal_ = UINT32_MAX;
  gain += drain_queue(cap, st);
  // The queue re-examines only the ends of applied moves, though a move also changes
  // what nodes that have those ends as candidates can do: passes over every node follow
  // while a pass still finds at least one move per kPassYield nodes (on strokes the
  // first pass leaves some 4 % of the travel to gain, on dots 0.2 %).
  for (int pass = 0; pass < kMaxPasses && !st.capped; ++pass) {
    const long before = st.moves_2opt + st.moves_oropt;
    for (const uint32_t v : tour_) push(v);
    gain += drain_queue(cap, st);
    if ((st.moves_2opt + st.moves_oropt - before) * kPassYield < N_) break;
  }
  st.gain += gain;
  st.reversed = reversed_;
}

void PathImprover::perturb(long kicks, uint64_t seed, Clock::time_point cap, ImproveStats& st) {
  if (N_ < 8 || kicks <= 0) return;
  Rng rng(seed);
  const uint32_t lmax = std::min(kMaxKickSegment, (N_ - 2) / 2);
  auto at = [&](uint32_t i) { return tour_[i % N_]; };
  logging_ = true;
  max_reversal_ = kKickReversals;
  deferred_.clear();
  // Trials go in rounds; when a whole round saves less than kRoundYield of the travel, the
  // rest would not pay for itself (so on long random strokes, whose repairs need long
  // reversals) and perturbation stops: a rule on results, so still deterministic.
  const long round = std::max(kMinRound, kicks / kRounds);
  double length = travel(), round_gain = 0;
  for (long t = 0; t < kicks && !st.capped; ++t) {
    if ((t & 15) == 0 && Clock::now() > cap) {
      st.capped = true;
      break;
    }
    if (t > 0 && t % round == 0) {
      if (round_gain < kRoundYield * length) break;
      length -= round_gain;
      round_gain = 0;
    }
    uint32_t i = rng.below(N_), l1 = 1 + rng.below(lmax), l2 = 1 + rng.below(lmax);
    // Cuts are moved one node on where they would split a stroke (each node has at
    // most one fixed edge, so the next edge is free).
    if (fixed(at(i), at(i + 1))) i = (i + 1) % N_;
    if (fixed(at(i + l1), at(i + l1 + 1))) ++l1;
    if (fixed(at(i + l1 + l2), at(i + l1 + l2 + 1))) ++l2;
    if (l1 + l2 + 2 > N_) continue;
    // a [b .. c] [d .. e] f  ->  a [d .. e] [b .. c] f
    const uint32_t a = at(i), b = at(i + 1), c = at(i + l1), d = at(i + l1 + 1), e = at(i + l1 + l2),
                   f = at(i + l1 + l2 + 1);
    const double cost = dist(a, d) + dist(e, b) + dist(c, f) - dist(a, b) - dist(c, d) - dist(e, f);
    log_.clear();
    const uint32_t pb = (i + 1) % N_;
    reverse_positions(pb, l1 + l2);
    reverse_positions(pb, l2);
    reverse_positions((pb + l2) % N_, l1);
    ++st.kicks;
    for (const uint32_t v : {a, b, c, d, e, f}) push(v);
    const double gain = drain_queue(cap, st);
    deferred_.clear();  // a kick's refused long moves are not pursued
    if (!st.capped && gain - cost > kEps) {
      ++st.kicks_kept;
      st.gain += gain - cost;
      round_gain += gain - cost;
      continue;
    }
    logging_ = false;
    for (auto it = log_.rbegin(); it != log_.rend(); ++it) reverse_positions(it->first, it->second);
    logging_ = true;
    while (count_ > 0) {  // left by the cap
      queued_[queue_[head_]] = 0;
      head_ = head_ + 1 == N_ ? 0 : head_ + 1;
      --count_;
    }
  }
  logging_ = false;
  max_reversal_ = UINT32_MAX;
  st.reversed = reversed_;
}

}  // namespace stipplot::plan::tour
