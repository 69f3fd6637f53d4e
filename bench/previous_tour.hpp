#pragma once
// The planner's tour as it was before its budget became work (greedy nearest neighbour,
// then 2-opt and Or-opt under a wall-clock budget, 2 s a drawing by default), kept
// verbatim as the benchmarks' in-process baseline. Not used by stipplot itself.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <vector>

#include "geometry/drawing.hpp"
#include "spatial/kdtree.hpp"
#include "spatial/knn.hpp"

namespace stipplot::bench::previous {

struct PreviousTourStats {
  double construct_seconds = 0, improve_seconds = 0;
  long moves_2opt = 0, moves_oropt = 0;
  bool budget_hit = false;
};

using Clock = std::chrono::steady_clock;

inline std::vector<uint32_t> greedy(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start) {
  spatial::PlaneTree tree = spatial::plane_tree(pts);
  std::vector<uint32_t> order;
  order.reserve(pts.size());
  Vec2 cur = start;
  while (tree.alive() > 0) {
    const uint32_t j = tree.take_nearest(spatial::plane_point(cur));
    order.push_back(j);
    cur = pts[j];
    if (partner[j] >= 0) {
      uint32_t k = static_cast<uint32_t>(partner[j]);
      tree.erase(k);
      order.push_back(k);
      cur = pts[k];
    }
  }
  return order;
}

// The open path as a cycle: the real nodes, then O (the start, fixed first) and D, a
// dummy at distance 0 from everything that closes the cycle. The edge O-D is fixed
// like a stroke's, so the cycle always reads O, path..., D.
class Improver {
 public:
  Improver(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
           const std::vector<uint32_t>& order, int k)
      : n_(static_cast<uint32_t>(pts.size())), N_(n_ + 2), O_(n_), D_(n_ + 1) {
    p_ = pts;
    p_.push_back(start);
    p_.push_back(start);
    partner_ = partner;
    partner_.push_back(static_cast<int32_t>(D_));
    partner_.push_back(static_cast<int32_t>(O_));
    tour_.reserve(N_);
    tour_.push_back(O_);
    tour_.insert(tour_.end(), order.begin(), order.end());
    tour_.push_back(D_);
    pos_.resize(N_);
    for (uint32_t i = 0; i < N_; ++i) pos_[tour_[i]] = i;
    build_neighbors(k);
  }

  void run(Clock::time_point deadline, PreviousTourStats& st) {
    std::deque<uint32_t> queue(tour_.begin(), tour_.end());
    std::vector<uint8_t> queued(N_, 1);
    long visits = 0;
    while (!queue.empty()) {
      if ((++visits & 63) == 0 && Clock::now() > deadline) {
        st.budget_hit = true;
        break;
      }
      uint32_t a = queue.front();
      queue.pop_front();
      queued[a] = 0;
      touched_.clear();
      if (try_2opt(a)) {
        ++st.moves_2opt;
      } else if (try_oropt(a)) {
        ++st.moves_oropt;
      } else {
        continue;
      }
      touched_.push_back(a);
      for (uint32_t t : touched_)
        if (!queued[t]) queued[t] = 1, queue.push_back(t);
    }
  }

  std::vector<uint32_t> path() const {
    // Read the cycle from O in the direction away from D.
    std::vector<uint32_t> out;
    out.reserve(n_);
    uint32_t i = pos_[O_];
    bool forward = tour_[(i + 1) % N_] != D_;
    for (uint32_t s = 1; s + 1 < N_; ++s) {
      uint32_t j = forward ? (i + s) % N_ : (i + N_ - s) % N_;
      out.push_back(tour_[j]);
    }
    return out;
  }

 private:
  static constexpr double kEps = 1e-10;

  double dist(uint32_t a, uint32_t b) const {
    if (a == D_ || b == D_) return 0;
    double dx = p_[a].x - p_[b].x, dy = p_[a].y - p_[b].y;
    return std::sqrt(dx * dx + dy * dy);
  }
  bool fixed(uint32_t a, uint32_t b) const { return partner_[a] == static_cast<int32_t>(b); }
  uint32_t next(uint32_t a) const { return tour_[pos_[a] + 1 == N_ ? 0 : pos_[a] + 1]; }
  uint32_t prev(uint32_t a) const { return tour_[pos_[a] == 0 ? N_ - 1 : pos_[a] - 1]; }

  void build_neighbors(int k) {
    k_ = static_cast<uint32_t>(std::max(1, k));
    stride_ = k_ + 1;
    nbr_.assign(static_cast<size_t>(N_) * stride_, UINT32_MAX);
    if (n_ == 0) return;
    // Only the real nodes are candidates (O and D sit at the end of p_).
    const spatial::PlaneKnn knn(p_, n_);
    std::vector<uint32_t> idx(k_ + 2);
    std::vector<double> d2(k_ + 2);
    // The real nodes and O, in tour order: consecutive queries then fall in the same part
    // of the tree (a third faster than index order on scattered points; same lists).
    for (uint32_t i : tour_) {
      if (i == D_) continue;
      const size_t got = knn.k_nearest(p_[i], k_ + 2, idx.data(), d2.data());
      uint32_t* row = &nbr_[static_cast<size_t>(i) * stride_];
      uint32_t m = 0;
      if (i < n_) row[m++] = D_;  // ending the path here costs nothing
      for (size_t j = 0; j < got && m < stride_; ++j)
        if (idx[j] != i && !fixed(i, idx[j])) row[m++] = idx[j];
    }
  }

  // Removes edges (a,b), (c,d) and adds (a,c), (b,d); a, b, ..., c, d must follow each
  // other in one direction round the cycle. Reverses whichever side is shorter.
  void move(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
    if (next(a) != b) {  // the mirror image: d, c, ..., b, a forward
      std::swap(a, d);
      std::swap(b, c);
    }
    uint32_t i = pos_[b], j = pos_[c];
    uint32_t len = (j + N_ - i) % N_ + 1;
    if (2 * len > N_) {
      i = pos_[d];
      j = pos_[a];
      len = N_ - len;
    }
    for (uint32_t s = 0; s < len / 2; ++s) {
      std::swap(tour_[i], tour_[j]);
      pos_[tour_[i]] = i;
      pos_[tour_[j]] = j;
      i = i + 1 == N_ ? 0 : i + 1;
      j = j == 0 ? N_ - 1 : j - 1;
    }
    touched_.insert(touched_.end(), {a, b, c, d});
  }

  bool try_2opt(uint32_t a) {
    for (int dir = 0; dir < 2; ++dir) {
      const uint32_t b = dir == 0 ? next(a) : prev(a);
      if (fixed(a, b)) continue;
      const double dab = dist(a, b);
      const uint32_t* row = &nbr_[static_cast<size_t>(a) * stride_];
      for (uint32_t j = 0; j < stride_ && row[j] != UINT32_MAX; ++j) {
        const uint32_t c = row[j];
        const double g1 = dab - dist(a, c);
        if (g1 <= kEps) break;
        const uint32_t d = dir == 0 ? next(c) : prev(c);
        if (c == b || d == a || fixed(c, d)) continue;
        if (g1 + dist(c, d) - dist(b, d) > kEps) {
          if (dir == 0)
            move(a, b, c, d);
          else
            move(b, a, d, c);
          return true;
        }
      }
    }
    return false;
  }

  bool try_oropt(uint32_t s1) {
    uint32_t seg[3];
    for (uint32_t len = 1; len <= 3 && len + 4 <= N_; ++len) {
      seg[len - 1] = len == 1 ? s1 : next(seg[len - 2]);
      const uint32_t s2 = seg[len - 1];
      if (s2 == O_ || s2 == D_ || s1 == O_ || s1 == D_) return false;
      const uint32_t p = prev(s1), nx = next(s2);
      if (fixed(p, s1) || fixed(s2, nx)) continue;
      const double removed = dist(p, s1) + dist(s2, nx) - dist(p, nx);
      if (removed <= kEps) continue;
      auto in_seg = [&](uint32_t v) { return std::find(seg, seg + len, v) != seg + len; };
      double best = kEps;
      uint32_t bx = 0, by = 0;
      bool brev = false;
      for (uint32_t end = 0; end < 2; ++end) {
        const uint32_t e = end == 0 ? s1 : s2;
        const uint32_t* row = &nbr_[static_cast<size_t>(e) * stride_];
        for (uint32_t j = 0; j < stride_ && row[j] != UINT32_MAX; ++j) {
          const uint32_t c = row[j];
          if (dist(e, c) >= removed) break;
          if (in_seg(c)) continue;
          // Insert between (c, next c) or (prev c, c); x, y in the forward direction.
          for (int side = 0; side < 2; ++side) {
            const uint32_t x = side == 0 ? c : prev(c), y = side == 0 ? next(c) : c;
            if (in_seg(x) || in_seg(y) || fixed(x, y)) continue;
            const double base = removed + dist(x, y);
            const double g_fwd = base - dist(x, s1) - dist(s2, y);
            const double g_rev = base - dist(x, s2) - dist(s1, y);
            if (g_fwd > best) best = g_fwd, bx = x, by = y, brev = false;
            if (g_rev > best) best = g_rev, bx = x, by = y, brev = true;
          }
        }
      }
      if (best > kEps) {
        // Three reversals: p S n..x y -> p x..n S^r y -> p n..x S^r y [-> S].
        move(p, s1, bx, by);
        move(p, bx, nx, s2);
        if (!brev) move(bx, s2, s1, by);
        return true;
      }
    }
    return false;
  }

  uint32_t n_, N_, O_, D_;
  std::vector<Vec2> p_;
  std::vector<int32_t> partner_;
  std::vector<uint32_t> tour_, pos_;
  uint32_t k_ = 8, stride_ = 9;
  std::vector<uint32_t> nbr_;
  std::vector<uint32_t> touched_;
};

inline std::vector<uint32_t> previous_tour(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                                          double seconds, PreviousTourStats* stats = nullptr) {
  PreviousTourStats st;
  auto t0 = Clock::now();
  std::vector<uint32_t> order = greedy(pts, partner, start);
  auto t1 = Clock::now();
  st.construct_seconds = std::chrono::duration<double>(t1 - t0).count();
  if (seconds > 0 && pts.size() >= 3) {
    Improver imp(pts, partner, start, order, 10);
    auto deadline = t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    imp.run(deadline, st);
    order = imp.path();
  }
  st.improve_seconds = std::chrono::duration<double>(Clock::now() - t1).count();
  if (stats) *stats = st;
  return order;
}

}  // namespace stipplot::bench::previous
