// forest_trails: every edge drawn, once or twice; trails that are walks; and the least
// retraced length + lift length x trails, checked against every choice of retraced edges
// on small random trees.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "methods/tree/trails.hpp"

using namespace stipplot;
using namespace stipplot::tree;

namespace {

struct Forest {
  std::vector<Vec2> pos;
  std::vector<TrailEdge> edges;
};

Forest random_forest(std::mt19937& rng, int n, int trees) {
  Forest f;
  std::uniform_real_distribution<double> u(0, 20);
  for (int i = 0; i < n; ++i) f.pos.push_back({u(rng), u(rng)});
  for (int i = trees; i < n; ++i) {  // vertex i joins an earlier one: a forest of `trees` trees
    std::uniform_int_distribution<int> pick(0, i - 1);
    f.edges.push_back({static_cast<uint32_t>(pick(rng)), static_cast<uint32_t>(i)});
  }
  return f;
}

double length(const Forest& f, const TrailEdge& e) {
  return std::hypot(f.pos[e.a].x - f.pos[e.b].x, f.pos[e.a].y - f.pos[e.b].y);
}

// Times each undirected edge is walked by the trails; REQUIREs consecutive vertices to be edges.
std::map<std::pair<uint32_t, uint32_t>, int> walked(const Forest& f, const TrailPlan& plan) {
  std::map<std::pair<uint32_t, uint32_t>, int> count, exists;
  for (const auto& e : f.edges) exists[{std::min(e.a, e.b), std::max(e.a, e.b)}] = 1;
  for (const auto& t : plan.trails) {
    REQUIRE(t.size() >= 2);
    for (size_t i = 1; i < t.size(); ++i) {
      const std::pair<uint32_t, uint32_t> k{std::min(t[i - 1], t[i]), std::max(t[i - 1], t[i])};
      REQUIRE(exists.count(k));
      ++count[k];
    }
  }
  return count;
}

// The best cost over every set of retraced edges, one tree: lifts x odd / 2 (what the DP
// minimises) or lifts x max(1, odd / 2) (the trails it takes: an all-even tree is one closed trail).
double brute_force(const Forest& f, double lift, bool at_least_one) {
  const size_t m = f.edges.size();
  double best = 1e300;
  for (uint32_t mask = 0; mask < (1u << m); ++mask) {
    std::vector<int> degree(f.pos.size(), 0);
    double retraced = 0;
    for (size_t k = 0; k < m; ++k) {
      const int times = (mask >> k) & 1 ? 2 : 1;
      degree[f.edges[k].a] += times, degree[f.edges[k].b] += times;
      if (times == 2) retraced += length(f, f.edges[k]);
    }
    int odd = 0;
    for (int d : degree) odd += d & 1;
    best = std::min(best, retraced + lift * (at_least_one ? std::max(1, odd / 2) : odd / 2));
  }
  return best;
}

}  // namespace

TEST_CASE("forest trails walk every edge once or twice, and no retrace gives the fewest Euler trails", "[tree][trails]") {
  std::mt19937 rng(7);
  for (int round = 0; round < 50; ++round) {
    const Forest f = random_forest(rng, 2 + round % 40, 1 + round % 3);
    for (double lift : {0.0, 2.0, 8.0, 1e6}) {
      const TrailPlan plan = forest_trails(f.pos, f.edges, lift);
      const auto count = walked(f, plan);
      REQUIRE(count.size() == f.edges.size());
      size_t twice = 0;
      for (const auto& [k, c] : count) {
        REQUIRE(c >= 1);
        REQUIRE(c <= 2);
        twice += c == 2;
      }
      REQUIRE(twice == plan.retraced_edges);
      if (lift == 0) {
        REQUIRE(plan.retraced_edges == 0);
        std::vector<int> degree(f.pos.size(), 0);
        for (const auto& e : f.edges) ++degree[e.a], ++degree[e.b];
        size_t odd = 0;
        for (int d : degree) odd += d & 1;
        REQUIRE(plan.trails.size() == odd / 2);
      }
      if (lift == 1e6) {  // a lift costs more than any retrace: one trail per tree with an edge
        std::vector<int> degree(f.pos.size(), 0);
        for (const auto& e : f.edges) ++degree[e.a], ++degree[e.b];
        size_t trees = 0;
        for (int r = 0; r < 1 + round % 3; ++r) trees += degree[static_cast<size_t>(r)] > 0;
        REQUIRE(plan.trails.size() == trees);
      }
    }
  }
}

TEST_CASE("forest trails retrace exactly where it pays: the least retraced length plus lifts, as an exhaustive search finds", "[tree][trails]") {
  std::mt19937 rng(11);
  for (int round = 0; round < 60; ++round) {
    const Forest f = random_forest(rng, 3 + round % 11, 1);  // up to 13 edges: 8192 choices
    for (double lift : {1.0, 5.0, 12.0, 40.0}) {
      const TrailPlan plan = forest_trails(f.pos, f.edges, lift);
      size_t open = 0;
      for (const auto& t : plan.trails) open += t.front() != t.back();
      INFO("round " << round << " lift " << lift << " trails " << plan.trails.size() << " retraced " << plan.retraced_length);
      (void)open;
      // Exact: the trails an all-even tree needs (one closed trail) counted too.
      const double cost = plan.retraced_length + lift * static_cast<double>(plan.trails.size());
      CHECK(cost == Approx(brute_force(f, lift, true)).margin(1e-9));
    }
  }
}

namespace {

double distance_to_segment(Vec2 p, Vec2 a, Vec2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0) : 0;
  return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

double distance_to_loops(Vec2 p, const std::vector<Polyline>& loops) {
  double best = 1e300;
  for (const auto& l : loops)
    for (size_t i = 1; i < l.pts.size(); ++i) best = std::min(best, distance_to_segment(p, l.pts[i - 1], l.pts[i]));
  return best;
}

// Sum and largest of the turns (radians, signed sum) between a closed loop's segments.
std::pair<double, double> turning(const Polyline& loop) {
  double sum = 0, largest = 0;
  const size_t m = loop.pts.size() - 1;
  for (size_t i = 0; i < m; ++i) {
    const Vec2 a = loop.pts[(i + m - 1) % m], b = loop.pts[i], c = loop.pts[(i + 1) % m];
    const double t = std::atan2((b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x),
                                (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y));
    sum += t;
    largest = std::max(largest, std::abs(t));
  }
  return {sum, largest};
}

}  // namespace

TEST_CASE("forest outlines: one closed loop a tree, passing every edge on both sides at the offset", "[tree][trails]") {
  std::mt19937 rng(11);
  const double offset = 0.15;
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 2 + trial % 25, trees = 1 + trial % 3;
    const Forest f = random_forest(rng, n, std::min(trees, n));
    // Trees with an edge: the roots some vertex joined.
    std::vector<int> root(f.pos.size());
    for (size_t v = 0; v < root.size(); ++v) root[v] = static_cast<int>(v);
    for (const auto& e : f.edges) root[e.b] = root[e.a];  // a joins an earlier vertex: its root is final
    std::set<int> with_edges;
    for (const auto& e : f.edges) with_edges.insert(root[e.a]);
    const std::vector<Polyline> loops = forest_outlines(f.pos, f.edges, offset, 0);
    INFO("trial " << trial);
    CHECK(loops.size() == with_edges.size());
    for (const auto& l : loops) {
      REQUIRE(l.pts.size() >= 3);
      CHECK(l.pts.front().x == l.pts.back().x);
      CHECK(l.pts.front().y == l.pts.back().y);
    }
    // Each edge's midpoint, moved the offset to either side, lies on a loop: the two passes.
    for (const auto& e : f.edges) {
      const Vec2 a = f.pos[e.a], b = f.pos[e.b];
      const double len = length(f, e);
      if (len < 1e-6) continue;
      const Vec2 n{-(b.y - a.y) / len, (b.x - a.x) / len}, m{(a.x + b.x) / 2, (a.y + b.y) / 2};
      CHECK(distance_to_loops({m.x + offset * n.x, m.y + offset * n.y}, loops) < 1e-9);
      CHECK(distance_to_loops({m.x - offset * n.x, m.y - offset * n.y}, loops) < 1e-9);
    }
    // No loop point farther than the offset from the forest.
    for (const auto& l : loops)
      for (const Vec2& p : l.pts) {
        double best = 1e300;
        for (const auto& e : f.edges) best = std::min(best, distance_to_segment(p, f.pos[e.a], f.pos[e.b]));
        CHECK(best <= offset * (1 + 1e-9));
      }
  }
}

TEST_CASE("forest outlines: a planar tree's loop turns once round, and two rounds of corner cutting halve its sharpest turn",
          "[tree][trails]") {
  // A comb: a spine with teeth up and down, every corner 90 degrees, the tips half circles.
  Forest f;
  for (int i = 0; i < 6; ++i) f.pos.push_back({2.0 * i, 0});
  for (int i = 0; i < 5; ++i) f.edges.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(i + 1)});
  for (int i = 0; i < 6; ++i) {
    f.pos.push_back({2.0 * i, i % 2 ? 1.5 : -1.5});
    f.edges.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(f.pos.size() - 1)});
  }
  const auto sharp = forest_outlines(f.pos, f.edges, 0.15, 0);
  const auto smooth = forest_outlines(f.pos, f.edges, 0.15, 2);
  REQUIRE(sharp.size() == 1);
  REQUIRE(smooth.size() == 1);
  const auto [sum0, max0] = turning(sharp[0]);
  const auto [sum2, max2] = turning(smooth[0]);
  CHECK(std::abs(std::abs(sum0) - 2 * M_PI) < 1e-9);
  CHECK(std::abs(std::abs(sum2) - 2 * M_PI) < 1e-9);
  CHECK(max0 == Approx(M_PI / 2).margin(1e-9));  // the mitred inner corners
  CHECK(max2 <= 0.5 * max0 + 1e-9);
  CHECK(smooth[0].pts.size() == 4 * (sharp[0].pts.size() - 1) + 1);
  // The loop is about twice the tree long (both sides), the tips' half circles adding a little.
  double tree_len = 0, loop_len = 0;
  for (const auto& e : f.edges) tree_len += length(f, e);
  for (size_t i = 1; i < sharp[0].pts.size(); ++i)
    loop_len += std::hypot(sharp[0].pts[i].x - sharp[0].pts[i - 1].x, sharp[0].pts[i].y - sharp[0].pts[i - 1].y);
  CHECK(loop_len > 2 * tree_len - 20 * 0.15);
  CHECK(loop_len < 2 * tree_len + 8 * M_PI * 0.15);
}
