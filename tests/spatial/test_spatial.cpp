// The spatial library against brute force: greedy nearest walks with deletion, exact
// MSTs, and the k-nearest lists.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "spatial/kdtree.hpp"
#include "spatial/knn.hpp"
#include "spatial/mst.hpp"
#include "test_util.hpp"
#include "util/rng.hpp"
#include "util/threads.hpp"

using namespace stipplot;

namespace {

double d2(Vec2 a, Vec2 b) { return (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y); }

// Random points, or points on a small integer grid (many exact ties and duplicates).
std::vector<Vec2> points(size_t n, bool grid, uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec2> p(n);
  for (auto& v : p)
    v = grid ? Vec2{double(rng.below(12)), double(rng.below(9))} : Vec2{rng.uniform() * 100, rng.uniform() * 60};
  return p;
}

// O(n^2) Prim: the MST weight.
double prim_weight(const std::vector<Vec2>& p) {
  const size_t n = p.size();
  std::vector<double> key(n, std::numeric_limits<double>::infinity());
  std::vector<char> in(n, 0);
  double total = 0;
  key[0] = 0;
  for (size_t step = 0; step < n; ++step) {
    size_t u = n;
    for (size_t i = 0; i < n; ++i)
      if (!in[i] && (u == n || key[i] < key[u])) u = i;
    in[u] = 1;
    total += std::sqrt(key[u]);
    for (size_t i = 0; i < n; ++i)
      if (!in[i]) key[i] = std::min(key[i], d2(p[u], p[i]));
  }
  return total;
}

}  // namespace

TEST_CASE("kd-tree greedy walk equals brute force - equally near points in a fixed order", "[spatial]") {
  for (bool grid : {false, true}) {
    for (size_t n : {1, 2, 9, 17, 300, 2000}) {
      const auto p = points(n, grid, 7 + n);
      auto tree = spatial::plane_tree(p);
      std::vector<char> used(n, 0);
      Vec2 cur{-1, -1};
      for (size_t step = 0; step < n; ++step) {
        size_t want = n;
        for (size_t i = 0; i < n; ++i)
          if (!used[i] && (want == n || d2(p[i], cur) < d2(p[want], cur))) want = i;  // first = lowest index
        const uint32_t got = tree.take_nearest(spatial::plane_point(cur));
        INFO("grid " << grid << " n " << n << " step " << step);
        REQUIRE(got < n);
        REQUIRE(!used[got]);
        REQUIRE(d2(p[got], cur) == d2(p[want], cur));
        if (!grid) REQUIRE(got == want);  // no ties: exactly the nearest
        used[got] = 1;
        cur = p[got];
        // erasing by index too: every third step drops one more point
        if (step % 3 == 0) {
          for (size_t i = 0; i < n; ++i)
            if (!used[i]) {
              tree.erase(static_cast<uint32_t>(i));
              used[i] = 1;
              ++step;
              break;
            }
        }
      }
      CHECK(tree.alive() == 0);
      CHECK(tree.take_nearest(spatial::plane_point(cur)) == spatial::kNone);
    }
  }
  // The same walk twice gives the same order, ties included.
  const auto p = points(3000, true, 5);
  auto walk = [&] {
    auto tree = spatial::plane_tree(p);
    std::vector<uint32_t> order;
    Vec2 cur{0, 0};
    while (tree.alive() > 0) order.push_back(tree.take_nearest(spatial::plane_point(cur))), cur = p[order.back()];
    return order;
  };
  CHECK(walk() == walk());
}

TEST_CASE("a kd-tree built on 1 and 3 threads is the same node for node", "[spatial][threads]") {
  // Large enough for its subtrees to be built as tasks; a grid makes many equal coordinates.
  for (const bool grid : {false, true}) {
    Rng rng(5);
    std::vector<Vec2> pts(300'001);
    for (auto& p : pts) {
      p = {rng.uniform() * 500, rng.uniform() * 300};
      if (grid) p = {std::round(p.x / 7) * 7, std::round(p.y / 7) * 7};
    }
    set_thread_count(1);
    const spatial::PlaneTree one = spatial::plane_tree(pts);
    set_thread_count(3);
    const spatial::PlaneTree three = spatial::plane_tree(pts);
    set_thread_count(0);
    INFO("grid " << grid);
    REQUIRE(one.nodes().size() == three.nodes().size());
    REQUIRE(one.nodes().size() > 60'000);
    bool same = true;
    for (size_t k = 0; k < one.nodes().size() && same; ++k) {
      const auto &a = one.nodes()[k], &b = three.nodes()[k];
      same = a.begin == b.begin && a.end == b.end && a.left == b.left && a.right == b.right && a.lo[0] == b.lo[0] &&
             a.lo[1] == b.lo[1] && a.hi[0] == b.hi[0] && a.hi[1] == b.hi[1] && a.alive == b.alive;
    }
    for (uint32_t k = 0; k < pts.size() && same; ++k) same = one.id(k) == three.id(k);
    CHECK(same);
    // Every node's children follow it, the leaves cover every point once, in order.
    uint32_t covered = 0;
    for (size_t k = 0; k < one.nodes().size(); ++k) {
      const auto& nd = one.nodes()[k];
      if (nd.leaf()) {
        CHECK(nd.begin == covered);
        covered = nd.end;
      } else {
        CHECK((nd.left == k + 1 && nd.right > nd.left && nd.right < one.nodes().size()));
      }
    }
    CHECK(covered == pts.size());
  }
}

TEST_CASE("Euclidean MST equals Prim's weight and spans the points", "[spatial][mst]") {
  for (bool grid : {false, true}) {
    for (size_t n : {0, 1, 2, 3, 50, 700}) {
      const auto p = points(n, grid, 100 + n);
      spatial::MstStats st;
      const auto edges = spatial::euclidean_mst(p, &st);
      INFO("grid " << grid << " n " << n);
      REQUIRE(edges.size() == (n < 2 ? 0 : n - 1));
      if (n < 2) continue;
      CHECK(spatial::total_cost(edges) == Approx(prim_weight(p)).epsilon(1e-12));
      REQUIRE(test::spans(edges, n));
      for (const auto& e : edges) CHECK(e.cost == Approx(std::sqrt(d2(p[e.a], p[e.b]))));
      CHECK(st.rounds >= 1);
    }
  }
}

TEST_CASE("k-nearest lists hold the k smallest distances, nearest first", "[spatial][knn]") {
  const auto p = points(500, true, 3);
  const spatial::PlaneKnn knn(p, p.size());
  std::vector<uint32_t> idx(12);
  std::vector<double> dist(12);
  for (size_t q = 0; q < p.size(); q += 7) {
    const size_t got = knn.k_nearest(p[q], 12, idx.data(), dist.data());
    REQUIRE(got == 12);
    std::vector<double> all;
    for (const auto& v : p) all.push_back(d2(v, p[q]));
    std::sort(all.begin(), all.end());
    for (size_t j = 0; j < got; ++j) {
      CHECK(d2(p[idx[j]], p[q]) == all[j]);
      CHECK(dist[j] == all[j]);
    }
  }
  const spatial::PlaneKnn few(p, 3);
  CHECK(few.k_nearest(p[0], 12, idx.data(), dist.data()) == 3);
}

TEST_CASE("k-nearest lists among heavily coincident points: coincident ones by index, in O(k log n)", "[spatial][knn]") {
  // 200,000 points on 25 positions: a query that opened every equally near box would
  // read 8,000 points each time (minutes for all of them).
  std::vector<Vec2> p(200000);
  for (size_t i = 0; i < p.size(); ++i) p[i] = {double(i % 5), double((i / 5) % 5)};
  const spatial::PlaneKnn knn(p, p.size());
  std::vector<uint32_t> idx(12);
  std::vector<double> dist(12);
  for (size_t q = 0; q < p.size(); ++q) {
    REQUIRE(knn.k_nearest(p[q], 12, idx.data(), dist.data()) == 12);
    if (q % 997 != 0) continue;
    for (size_t j = 0; j < 12; ++j) {
      CHECK(dist[j] == 0);
      CHECK(p[idx[j]] == p[q]);
      if (j > 0) CHECK(idx[j] > idx[j - 1]);
    }
    CHECK(idx[0] == q % 25);  // the lowest index at that position
  }
  // Beyond the coincident ones: the next position's points, nearest first.
  const std::vector<Vec2> two = {{0, 0}, {0, 0}, {1, 0}, {1, 0}, {3, 0}};
  const spatial::PlaneKnn small(two, two.size());
  REQUIRE(small.k_nearest({0.2, 0}, 5, idx.data(), dist.data()) == 5);
  CHECK(std::vector<uint32_t>(idx.begin(), idx.begin() + 5) == std::vector<uint32_t>{0, 1, 2, 3, 4});
  CHECK(dist[2] == Approx(0.64));
}
