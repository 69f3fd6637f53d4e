// forest_trails: every edge drawn, once or twice; trails that are walks; and the least
// retraced length + lift length x trails, checked against every choice of retraced edges
// on small random trees.
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <random>

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
