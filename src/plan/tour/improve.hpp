#pragma once
// Local search on an open path: 2-opt and Or-opt over candidate lists, then perturbation
// (segment-swap kicks, each kept only if the local search after it shortens the path).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <vector>

#include "candidates.hpp"
#include "geometry/drawing.hpp"

namespace stipplot::plan::tour {

using Clock = std::chrono::steady_clock;

struct ImproveStats {
  long moves_2opt = 0, moves_oropt = 0;
  long kicks = 0, kicks_kept = 0;
  long long reversed = 0;   // array elements moved by reversals: the improver's main cost
  double gain = 0;          // how much shorter the path got, by the moves' own reckoning
  bool capped = false;      // stopped by the wall-clock cap before its work was done
};

// The path as a cycle on an array: the real nodes, then O (the start) and D, a dummy at
// distance 0 from every node, so the cycle reads O, path..., D and the path may end
// anywhere. O-D is fixed like a stroke's two ends; a move never removes a fixed edge.
class PathImprover {
 public:
  PathImprover(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
               const std::vector<uint32_t>& order, const Candidates& cand);

  // 2-opt and Or-opt (segments of up to three nodes, or strokes, in either orientation)
  // from every node, re-examining the ends of each applied move, to a local optimum:
  // O(k) per examined node plus the reversals (the shorter side of the cycle).
  void local_search(Clock::time_point cap, ImproveStats& st);
  // `kicks` perturbations, each O(segment) plus the local search it triggers, undone
  // unless the path got shorter. Deterministic for a given seed.
  void perturb(long kicks, uint64_t seed, Clock::time_point cap, ImproveStats& st);
  std::vector<uint32_t> path() const;

 private:
  double dist(uint32_t a, uint32_t b) const {
    if (a == D_ || b == D_) return 0;
    const double dx = p_[a].x - p_[b].x, dy = p_[a].y - p_[b].y;
    return std::sqrt(dx * dx + dy * dy);
  }
  bool fixed(uint32_t a, uint32_t b) const { return partner_[a] == static_cast<int32_t>(b); }
  uint32_t next(uint32_t a) const { return tour_[pos_[a] + 1 == N_ ? 0 : pos_[a] + 1]; }
  uint32_t prev(uint32_t a) const { return tour_[pos_[a] == 0 ? N_ - 1 : pos_[a] - 1]; }
  uint32_t succ(uint32_t a, bool fwd) const { return fwd ? next(a) : prev(a); }
  // Pen-up travel: the cycle's edges less the strokes' own. O(n).
  double travel() const {
    double s = 0;
    for (uint32_t i = 0; i < N_; ++i) {
      const uint32_t a = tour_[i], b = tour_[i + 1 == N_ ? 0 : i + 1];
      if (!fixed(a, b)) s += dist(a, b);
    }
    return s;
  }

  // Elements a 2-opt move between a-b and c-d reverses (b..c or the other side).
  uint32_t reversal_length(uint32_t b, uint32_t c) const {
    const uint32_t len = (pos_[c] + N_ - pos_[b]) % N_ + 1;
    return std::min(len, N_ - len);
  }
  void reverse_positions(uint32_t i, uint32_t len);
  void move(uint32_t a, uint32_t b, uint32_t c, uint32_t d);
  double try_2opt(uint32_t a);
  double try_oropt(uint32_t a);
  double try_oropt_from(uint32_t s1, bool fwd);
  double drain_queue(Clock::time_point cap, ImproveStats& st);
  void push(uint32_t v);
  template <class F>
  void for_candidates(uint32_t a, F&& f) const;

  uint32_t n_, N_, O_, D_;
  std::vector<Vec2> p_;
  std::vector<int32_t> partner_;
  std::vector<uint32_t> tour_, pos_;
  const Candidates& cand_;
  // Work queue (FIFO ring) of nodes to examine, and whether each is in it.
  std::vector<uint32_t> queue_;
  size_t head_ = 0, count_ = 0;
  std::vector<uint8_t> queued_;
  std::vector<uint32_t> touched_;
  // Reversals applied since a kick (start, length), replayed backwards to undo it.
  bool logging_ = false;
  std::vector<std::pair<uint32_t, uint32_t>> log_;
  long long reversed_ = 0;
  uint32_t max_reversal_ = UINT32_MAX;  // moves that would reverse more are not taken
  bool capped_out_ = false;             // the node's best move was refused for its reversal
  std::vector<uint32_t> deferred_;      // such nodes, for the next stage
  uint64_t check_ = 0;
};

}  // namespace stipplot::plan::tour
