#include "plan/tour.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "spatial/kdtree.hpp"
#include "tour/candidates.hpp"
#include "tour/construct.hpp"
#include "tour/improve.hpp"

namespace stipplot::plan {

namespace {

using tour::Clock;

double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// Nodes renumbered in the kd-tree's leaf order, which keeps near points near in memory
// (the improver's reads follow space). rank[old] = new, id[new] = old.
struct SpatialOrder {
  std::vector<uint32_t> id, rank;
  std::vector<Vec2> pts;
  std::vector<int32_t> partner;
};

SpatialOrder spatial_order(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner) {
  const uint32_t n = static_cast<uint32_t>(pts.size());
  const spatial::PlaneTree tree = spatial::plane_tree(pts);
  SpatialOrder s;
  s.id.resize(n);
  s.rank.resize(n);
  s.pts.resize(n);
  s.partner.resize(n);
  for (uint32_t k = 0; k < n; ++k) {
    s.id[k] = tree.id(k);
    s.rank[s.id[k]] = k;
    s.pts[k] = pts[s.id[k]];
  }
  for (uint32_t k = 0; k < n; ++k) {
    const int32_t p = partner[s.id[k]];
    s.partner[k] = p < 0 ? -1 : static_cast<int32_t>(s.rank[static_cast<uint32_t>(p)]);
  }
  return s;
}

Clock::time_point deadline(Clock::time_point t0, double seconds) {
  // Far enough to never trip, near enough not to overflow the clock.
  const double s = std::min(seconds, 1e7);
  return t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

std::vector<uint32_t> plan_tour(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                                const TourOptions& opt, TourStats* stats) {
  TourStats st;
  const auto t0 = Clock::now();
  const SpatialOrder s = spatial_order(pts, partner);
  const bool improve = opt.improve && opt.seconds_cap > 0 && pts.size() >= 3;
  tour::Candidates cand;
  if (improve || opt.start == TourStart::GreedyEdge) cand = tour::nearest_candidates(s.pts, s.partner, start, opt.neighbors);
  std::vector<uint32_t> order = opt.start == TourStart::GreedyEdge
                                    ? tour::greedy_edge_path(s.pts, s.partner, start, cand)
                                    : tour::nearest_neighbour_path(s.pts, s.partner, start);
  const auto t1 = Clock::now();
  st.construct_seconds = seconds_between(t0, t1);
  if (improve) {
    const auto cap = deadline(t0, opt.seconds_cap);
    tour::PathImprover imp(s.pts, s.partner, start, order, cand);
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
  for (uint32_t& v : order) v = s.id[v];
  if (stats) *stats = st;
  return order;
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
