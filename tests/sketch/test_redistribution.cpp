// Secord's redistribution: the m equation, its degenerate cases, and the placement of
// points by inverting the CDF at a low-discrepancy sequence.
#include <catch2/catch.hpp>
#include <cmath>

#include "methods/sketch/redistribution.hpp"
#include "util/rng.hpp"

using namespace stipplot;
using namespace stipplot::sketch;

namespace {
double sum_q(const std::vector<float>& p, const PointCount& pc) {
  // Recomputed here in double from the definition, not through densities().
  const double pmax = max_probability();
  double s = 0;
  for (float v : p) s += 1.0 - std::pow(1.0 - std::min<double>(std::max(0.0f, v), pmax), 1.0 / pc.m);
  return s;
}

std::vector<float> random_field(size_t n, uint64_t seed, double zero_share) {
  Rng rng(seed);
  std::vector<float> p(n);
  for (auto& v : p) v = rng.uniform() < zero_share ? 0.0f : static_cast<float>(rng.uniform());
  return p;
}
}  // namespace

TEST_CASE("m solves sum (1-p)^(1/m) = n-1, so sum q = 1", "[sketch]") {
  for (uint64_t seed : {1, 2, 3}) {
    for (double zeros : {0.0, 0.5, 0.99}) {
      for (size_t n : {size_t{3}, size_t{100}, size_t{10000}, size_t{200000}}) {
        auto p = random_field(n, seed, zeros);
        size_t positive = 0;
        for (float v : p) positive += v > 0;
        if (positive < 2) continue;
        PointCount pc = solve_point_count(p);
        INFO("n=" << n << " zeros=" << zeros << " m=" << pc.m);
        REQUIRE(!pc.degenerate);
        REQUIRE(pc.m > 0);
        CHECK(sum_q(p, pc) == Approx(1.0).epsilon(1e-9));
        // the equation itself, as the paper writes it
        double lhs = 0;
        const double pmax = max_probability();
        for (float v : p) lhs += std::pow(1.0 - std::min<double>(v, pmax), 1.0 / pc.m);
        CHECK(lhs == Approx(static_cast<double>(n) - 1).epsilon(1e-10));
        // densities() agrees and sums to 1
        auto q = densities(p, pc);
        double sq = 0;
        for (float v : q) sq += v;
        CHECK(sq == Approx(1.0).epsilon(1e-5));
        CHECK(pc.iterations < 30);
        // the naive bisection finds the same m
        CHECK(solve_point_count_bisection(p).m == Approx(pc.m).epsilon(1e-9));
      }
    }
  }
}

TEST_CASE("m for small p is about sum p (one point per expected occupied cell)", "[sketch]") {
  std::vector<float> p(10000, 0.01f);
  PointCount pc = solve_point_count(p);
  CHECK(pc.m == Approx(-10000 * std::log1p(-0.01)).epsilon(0.01));
  CHECK(pc.m == Approx(100).epsilon(0.02));
}

TEST_CASE("degenerate fields: p = 0, p = 1 everywhere, tiny images", "[sketch]") {
  SECTION("p = 0 everywhere: no points") {
    PointCount pc = solve_point_count(std::vector<float>(1000, 0.0f));
    CHECK(pc.m == 0);
    CHECK(pc.degenerate);
    CHECK(place_points(densities(std::vector<float>(1000, 0.0f), pc), 100, 10, 0, 1).empty());
  }
  SECTION("p = 1 everywhere: capped at kMaxPointsPerCell points per cell") {
    std::vector<float> p(1000, 1.0f);
    PointCount pc = solve_point_count(p);
    CHECK(!pc.degenerate);
    CHECK(std::isfinite(pc.m));
    CHECK(pc.m == Approx(kMaxPointsPerCell * 1000).epsilon(0.01));
    CHECK(sum_q(p, pc) == Approx(1.0).epsilon(1e-9));
  }
  SECTION("one cell with p > 0, and one-cell images") {
    for (float v : {0.3f, 1.0f}) {
      std::vector<float> p(50, 0.0f);
      p[17] = v;
      PointCount pc = solve_point_count(p);
      CHECK(pc.degenerate);
      CHECK(pc.m == Approx(-std::log1p(-std::min<double>(v, max_probability()))));
      PointCount one = solve_point_count({v});
      CHECK(one.degenerate);
      CHECK(std::isfinite(one.m));
    }
    CHECK(solve_point_count({}).m == 0);
  }
  SECTION("two cells, tiny p: m tiny but finite") {
    std::vector<float> p = {1e-6f, 1e-6f, 0.0f};
    PointCount pc = solve_point_count(p);
    CHECK(std::isfinite(pc.m));
    CHECK(pc.m > 0);
    CHECK(sum_q(p, pc) == Approx(1.0).epsilon(1e-6));
  }
  SECTION("NaN counts as 0") {
    std::vector<float> p = {std::nanf(""), 0.5f, 0.5f};
    CHECK(std::isfinite(solve_point_count(p).m));
  }
}

TEST_CASE("points follow q and are deterministic per seed", "[sketch]") {
  const int w = 64, h = 32;
  std::vector<float> q(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) q[y * w + x] = x < w / 2 ? 3.0f : 1.0f;
  auto a = place_points(q, w, h, 8000, 7);
  REQUIRE(a.size() == 8000);
  size_t left = 0;
  for (auto pt : a) {
    REQUIRE(pt.x >= 0);
    REQUIRE(pt.x < w);
    REQUIRE(pt.y >= 0);
    REQUIRE(pt.y < h);
    left += pt.x < w / 2;
  }
  CHECK(static_cast<double>(left) / a.size() == Approx(0.75).margin(0.005));
  auto b = place_points(q, w, h, 8000, 7);
  auto c = place_points(q, w, h, 8000, 8);
  bool same = true, differ = false;
  for (size_t i = 0; i < a.size(); ++i) {
    same = same && a[i].x == b[i].x && a[i].y == b[i].y;
    differ = differ || a[i].x != c[i].x;
  }
  CHECK(same);
  CHECK(differ);
}

TEST_CASE("low-discrepancy placement spreads points more evenly than independent draws", "[sketch]") {
  // Uniform q: count the points in each 4x4 block; independent draws give Poisson
  // variance (= mean), the R2 sequence far less.
  const int w = 128, h = 128, block = 4;
  std::vector<float> q(w * h, 1.0f);
  const size_t count = 16384;  // 16 per block
  auto variance = [&](const std::vector<Point>& pts) {
    std::vector<int> c((w / block) * (h / block), 0);
    for (auto pt : pts) c[(static_cast<int>(pt.y) / block) * (w / block) + static_cast<int>(pt.x) / block]++;
    double mean = static_cast<double>(pts.size()) / c.size(), v = 0;
    for (int k : c) v += (k - mean) * (k - mean);
    return v / c.size();
  };
  const double lds = variance(place_points(q, w, h, count, 3));
  const double rnd = variance(place_points_random(q, w, h, count, 3));
  INFO("block count variance: lds " << lds << ", random " << rnd);
  CHECK(rnd > 10);
  CHECK(lds < rnd / 4);
}
