#include "plan/tour.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>

#include "spatial/kdtree.hpp"
#include "tour/candidates.hpp"
#include "tour/construct.hpp"
#include "tour/improve.hpp"
#include "util/threads.hpp"

namespace stipplot::plan {

namespace {

using tour::Clock;

double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// Nodes renumbered in the kd-tree's leaf order, which keeps near points near in memory
// (the improver's reads follow space). id[new] = old.
struct SpatialOrder {
  std::vector<uint32_t> id;
  std::vector<Vec2> pts;
  std::vector<int32_t> partner;
};

SpatialOrder spatial_order(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner) {
  const uint32_t n = static_cast<uint32_t>(pts.size());
  const spatial::PlaneTree tree = spatial::plane_tree(pts);
  SpatialOrder s;
  s.id.resize(n);
  std::vector<uint32_t> rank(n);  // rank[old] = new
  s.pts.resize(n);
  s.partner.resize(n);
  for (uint32_t k = 0; k < n; ++k) {
    s.id[k] = tree.id(k);
    rank[s.id[k]] = k;
    s.pts[k] = pts[s.id[k]];
  }
  for (uint32_t k = 0; k < n; ++k) {
    const int32_t p = partner[s.id[k]];
    s.partner[k] = p < 0 ? -1 : static_cast<int32_t>(rank[static_cast<uint32_t>(p)]);
  }
  return s;
}

Clock::time_point deadline(Clock::time_point t0, double seconds) {
  // Far enough to never trip, near enough not to overflow the clock.
  const double s = std::min(seconds, 1e7);
  return t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

namespace {

// A path constructed and ready to improve: the nodes in kd-tree order, their candidates
// and the constructed order (in that numbering).
struct Built {
  SpatialOrder s;
  tour::Candidates cand;
  std::vector<uint32_t> order;
  bool improve = false;
  Clock::time_point t0;
  TourStats st;
};

Built build(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start, const TourOptions& opt) {
  Built b;
  b.t0 = Clock::now();
  b.s = spatial_order(pts, partner);
  b.improve = opt.improve && opt.seconds_cap > 0 && pts.size() >= 3;
  if (b.improve || opt.start == TourStart::GreedyEdge)
    b.cand = tour::nearest_candidates(b.s.pts, b.s.partner, start, opt.neighbors);
  b.order = opt.start == TourStart::GreedyEdge ? tour::greedy_edge_path(b.s.pts, b.s.partner, start, b.cand)
                                               : tour::nearest_neighbour_path(b.s.pts, b.s.partner, start);
  b.st.construct_seconds = seconds_between(b.t0, Clock::now());
  return b;
}

// Improves a built path (freeing it) and returns it in the callers' numbering.
std::vector<uint32_t> finish(Built b, Vec2 start, const TourOptions& opt, TourStats* stats) {
  TourStats st = b.st;
  const auto t1 = Clock::now();
  std::vector<uint32_t> order = std::move(b.order);
  if (b.improve) {
    const auto cap = deadline(b.t0, opt.seconds_cap);
    tour::PathImprover imp(b.s.pts, b.s.partner, start, order, b.cand);
    tour::ImproveStats is;
    imp.local_search(cap, is);
    if (!is.capped) imp.perturb(opt.kicks, opt.seed, cap, is);
    order = imp.path();
    st.moves_2opt = is.moves_2opt;
    st.moves_oropt = is.moves_oropt;
    st.kicks = is.kicks;
    st.kicks_kept = is.kicks_kept;
    st.reversed = is.reversed;
    st.gain = is.gain;
    st.capped = is.capped;
  }
  st.improve_seconds = seconds_between(t1, Clock::now());
  for (uint32_t& v : order) v = b.s.id[v];
  if (stats) *stats = st;
  return order;
}

// Paths of more nodes than this are planned as two halves of the plane, in parallel: the
// improvement's reversals cost O(n) each, so halves also cost less work in all. The split
// depends on the nodes only, never on the thread count: the same path on any machine.
constexpr size_t kSplitNodes = 250'000;

// One half of a split: its nodes (renumbered) and their numbers in the whole.
struct Half {
  std::vector<Vec2> pts;
  std::vector<int32_t> partner;
  std::vector<uint32_t> id;
};

// Splits at the median of the longer axis (a stroke's two ends stay together, on the side
// of its first end), plans the half the start lies in from the start and the other from
// the start's nearest point on the split line, both at once, and joins them: one pen-up
// jump more than a whole path has, at most the sheet's size. O(n log n) and the halves.
// `release`: `pts` itself when the caller gave it up (freed once the halves are made).
std::vector<uint32_t> plan_split(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                                 const TourOptions& opt, TourStats* stats, std::vector<Vec2>* release) {
  const uint32_t n = static_cast<uint32_t>(pts.size());
  std::vector<uint32_t> units;  // a lone node, or a stroke's first end
  units.reserve(n);
  Vec2 lo = pts[0], hi = pts[0];
  for (uint32_t i = 0; i < n; ++i) {
    lo = {std::min(lo.x, pts[i].x), std::min(lo.y, pts[i].y)};
    hi = {std::max(hi.x, pts[i].x), std::max(hi.y, pts[i].y)};
    if (partner[i] < 0 || static_cast<uint32_t>(partner[i]) > i) units.push_back(i);
  }
  const bool along_x = hi.x - lo.x >= hi.y - lo.y;
  auto key = [&](uint32_t i) { return along_x ? pts[i].x : pts[i].y; };
  // Ties broken by node number: the split is a function of the nodes alone.
  auto before = [&](uint32_t a, uint32_t b) { return key(a) < key(b) || (key(a) == key(b) && a < b); };
  const auto mid = units.begin() + static_cast<std::ptrdiff_t>(units.size() / 2);
  std::nth_element(units.begin(), mid, units.end(), before);
  const double cut = key(*mid);
  const bool start_low = (along_x ? start.x : start.y) < cut;
  Half half[2];  // [0] the start's side, planned first
  for (auto it = units.begin(); it != units.end(); ++it) {
    Half& h = half[(it < mid) == start_low ? 0 : 1];
    const uint32_t i = *it;
    h.pts.push_back(pts[i]);
    h.id.push_back(i);
    h.partner.push_back(-1);
    if (partner[i] >= 0) {
      const uint32_t j = static_cast<uint32_t>(partner[i]);
      h.partner.back() = static_cast<int32_t>(h.pts.size());
      h.pts.push_back(pts[j]);
      h.id.push_back(j);
      h.partner.push_back(static_cast<int32_t>(h.pts.size() - 2));
    }
  }
  std::vector<uint32_t>().swap(units);  // a million-node path's memory is its budget
  if (release) std::vector<Vec2>().swap(*release);  // the halves hold their copies (pts is *release)
  const Vec2 on_cut = along_x ? Vec2{cut, std::clamp(start.y, lo.y, hi.y)} : Vec2{std::clamp(start.x, lo.x, hi.x), cut};
  const Vec2 from[2] = {start, on_cut};
  std::vector<uint32_t> order[2];
  TourStats st[2];
  TourOptions o[2] = {opt, opt};
  Built built[2];
  for (int k = 0; k < 2; ++k) {
    const double share = static_cast<double>(half[k].pts.size()) / n;
    o[k].kicks = std::lround(static_cast<double>(opt.kicks) * share);
    o[k].seconds_cap = opt.seconds_cap * share;
    o[k].seed = opt.seed + static_cast<uint64_t>(k);
  }
  auto build_half = [&](int k) {
    built[k] = build(half[k].pts, half[k].partner, from[k], o[k]);
    std::vector<Vec2>().swap(half[k].pts);
    std::vector<int32_t>().swap(half[k].partner);
  };
  if (thread_count() < 2) {  // one half at a time: the same paths, half the memory
    for (int k = 0; k < 2; ++k) {
      build_half(k);
      order[k] = finish(std::move(built[k]), from[k], o[k], &st[k]);
    }
  } else {
    // Each half built and improved on a thread of its own.
    std::exception_ptr failed[2];
#pragma omp parallel for num_threads(2) schedule(static, 1)
    for (int k = 0; k < 2; ++k) {
      try {
        build_half(k);
        order[k] = finish(std::move(built[k]), from[k], o[k], &st[k]);
      } catch (...) {
        failed[k] = std::current_exception();  // an exception must not leave an OpenMP region
      }
    }
    for (const auto& e : failed)
      if (e) std::rethrow_exception(e);
  }
  std::vector<uint32_t> out;
  out.reserve(n);
  for (int k = 0; k < 2; ++k) {
    for (uint32_t v : order[k]) out.push_back(half[k].id[v]);
    std::vector<uint32_t>().swap(order[k]);
  }
  if (stats) {
    TourStats& s = *stats;
    s = TourStats{};
    for (const TourStats& t : st) {
      s.construct_seconds = std::max(s.construct_seconds, t.construct_seconds);
      s.improve_seconds = std::max(s.improve_seconds, t.improve_seconds);
      s.moves_2opt += t.moves_2opt, s.moves_oropt += t.moves_oropt;
      s.kicks += t.kicks, s.kicks_kept += t.kicks_kept, s.reversed += t.reversed;
      s.gain += t.gain;
      s.capped = s.capped || t.capped;
    }
  }
  return out;
}

}  // namespace

std::vector<uint32_t> plan_tour(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                                const TourOptions& opt, TourStats* stats) {
  if (pts.size() > kSplitNodes && opt.improve && opt.start == TourStart::GreedyEdge)
    return plan_split(pts, partner, start, opt, stats, nullptr);
  return finish(build(pts, partner, start, opt), start, opt, stats);
}

std::vector<uint32_t> plan_tour(std::vector<Vec2>&& pts, const std::vector<int32_t>& partner, Vec2 start,
                                const TourOptions& opt, TourStats* stats) {
  if (pts.size() > kSplitNodes && opt.improve && opt.start == TourStart::GreedyEdge)
    return plan_split(pts, partner, start, opt, stats, &pts);
  return finish(build(pts, partner, start, opt), start, opt, stats);
}

double tour_travel(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                   const std::vector<uint32_t>& order) {
  double s = 0;
  Vec2 cur = start;
  for (size_t i = 0; i < order.size(); ++i) {
    const uint32_t v = order[i];
    const bool joined = i > 0 && partner[v] == static_cast<int32_t>(order[i - 1]);
    if (!joined) s += std::hypot(pts[v].x - cur.x, pts[v].y - cur.y);
    cur = pts[v];
  }
  return s;
}

}  // namespace stipplot::plan
