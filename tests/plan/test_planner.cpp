// Planner: tree strokes, joins, tour order, fills, stats.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>

#include "spatial/mst.hpp"
#include "plan/planner.hpp"
#include "drivers/motion/plan_stats.hpp"
#include "plan/strokes.hpp"
#include "util/error.hpp"
#include "util/rng.hpp"
#include "util/threads.hpp"

using namespace stipplot;

namespace {

using SegKey = std::tuple<double, double, double, double>;

SegKey seg_key(Vec2 a, Vec2 b) {
  if (std::tie(b.x, b.y) < std::tie(a.x, a.y)) std::swap(a, b);
  return {a.x, a.y, b.x, b.y};
}

std::map<SegKey, int> segments_of(const std::vector<Polyline>& lines) {
  std::map<SegKey, int> m;
  for (const auto& l : lines)
    for (size_t k = 1; k < l.pts.size(); ++k) ++m[seg_key(l.pts[k - 1], l.pts[k])];
  return m;
}

std::map<SegKey, int> segments_of(const std::vector<Stroke>& strokes) {
  std::map<SegKey, int> m;
  for (const auto& s : strokes)
    for (size_t k = 1; k < s.pts.size(); ++k) ++m[seg_key(s.pts[k - 1], s.pts[k])];
  return m;
}

size_t odd_vertices(const std::vector<Polyline>& lines) {
  std::map<std::pair<double, double>, int> deg;
  for (const auto& l : lines) {
    ++deg[{l.pts.front().x, l.pts.front().y}];
    ++deg[{l.pts.back().x, l.pts.back().y}];
  }
  size_t odd = 0;
  for (auto& [_, d] : deg) odd += d % 2;
  return odd;
}

std::vector<Vec2> random_points(size_t n, double side, uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec2> p(n);
  for (auto& v : p) v = {rng.uniform() * side, rng.uniform() * side};
  return p;
}

// Tree edges as 2-point polylines, shuffled and randomly reversed, as a method might emit them.
std::vector<Polyline> as_segments(const std::vector<Vec2>& pts, const std::vector<std::pair<uint32_t, uint32_t>>& edges,
                                  uint64_t seed) {
  Rng rng(seed);
  std::vector<Polyline> lines;
  for (auto [a, b] : edges) {
    if (rng.below(2)) std::swap(a, b);
    lines.push_back({{pts[a], pts[b]}});
  }
  for (size_t i = lines.size(); i > 1; --i) std::swap(lines[i - 1], lines[rng.below(static_cast<uint32_t>(i))]);
  return lines;
}

void check_tree(const std::vector<Polyline>& lines) {
  const auto strokes = plan::join_polylines(lines, 1e-6);
  const size_t odd = odd_vertices(lines);
  CHECK(strokes.size() == std::max<size_t>(1, odd / 2));
  CHECK(segments_of(strokes) == segments_of(lines));
}


}  // namespace

TEST_CASE("tree strokes: random recursive trees need half their odd vertices", "[plan][tree]") {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    Rng rng(seed);
    const size_t n = 2 + rng.below(300);
    auto pts = random_points(n, 100, seed + 100);
    std::vector<std::pair<uint32_t, uint32_t>> edges;
    for (uint32_t i = 1; i < n; ++i) edges.push_back({rng.below(i), i});
    check_tree(as_segments(pts, edges, seed));
  }
}

TEST_CASE("tree strokes: Euclidean MSTs, paths and stars", "[plan][tree]") {
  auto pts = random_points(2000, 100, 7);
  std::vector<std::pair<uint32_t, uint32_t>> mst;
  for (const auto& e : spatial::euclidean_mst(pts)) mst.push_back({e.a, e.b});
  REQUIRE(mst.size() == pts.size() - 1);
  check_tree(as_segments(pts, mst, 1));

  std::vector<std::pair<uint32_t, uint32_t>> path, star;
  for (uint32_t i = 1; i < 50; ++i) path.push_back({i - 1, i}), star.push_back({0, i});
  auto path_lines = as_segments(pts, path, 2);
  CHECK(plan::join_polylines(path_lines, 1e-6).size() == 1);
  check_tree(path_lines);
  auto star_lines = as_segments(pts, star, 3);
  CHECK(plan::join_polylines(star_lines, 1e-6).size() == 49 / 2 + 1);  // 49 leaves + odd centre = 50 odd
  check_tree(star_lines);

  // A forest: two stars far apart are planned separately.
  auto forest = star_lines;
  for (auto l : star_lines) {
    for (auto& p : l.pts) p.x += 500;
    forest.push_back(l);
  }
  CHECK(plan::join_polylines(forest, 1e-6).size() == 2 * 25);
}

TEST_CASE("EMST is exact against Prim on small sets", "[plan][tree]") {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    auto pts = random_points(300, 50, seed);
    const size_t n = pts.size();
    std::vector<double> best(n, std::numeric_limits<double>::infinity());
    std::vector<char> in(n, 0);
    best[0] = 0;
    double prim = 0;
    for (size_t it = 0; it < n; ++it) {
      size_t u = n;
      for (size_t v = 0; v < n; ++v)
        if (!in[v] && (u == n || best[v] < best[u])) u = v;
      in[u] = 1;
      prim += best[u];
      for (size_t v = 0; v < n; ++v)
        if (!in[v]) best[v] = std::min(best[v], std::hypot(pts[u].x - pts[v].x, pts[u].y - pts[v].y));
    }
    CHECK(spatial::total_cost(spatial::euclidean_mst(pts)) == Approx(prim).epsilon(1e-12));
  }
}

TEST_CASE("polylines whose ends meet within the tolerance are joined", "[plan][join]") {
  // A - B - C - D chain of three polylines, given out of order, one reversed, with 0.03 mm gaps.
  std::vector<Polyline> lines = {
      {{{20, 0}, {25, 5}, {30, 0.0}}},     // C -> D
      {{{10.03, 0}, {5, 5}, {0, 0}}},      // B -> A (reversed), 0.03 from the next
      {{{10, 0}, {15, 5}, {20.02, 0}}},    // B -> C
  };
  auto s = plan::join_polylines(lines, 0.05);
  REQUIRE(s.size() == 1);
  CHECK(s[0].pts.size() == 9);  // 0.02/0.03 gaps kept as tiny pen-down steps, nothing dropped
  CHECK(plan::join_polylines(lines, 0.01).size() == 3);
  // A closed square made of four polylines is one closed stroke.
  std::vector<Polyline> square = {{{{0, 0}, {1, 0}}}, {{{1, 1}, {1, 0}}}, {{{1, 1}, {0, 1}}}, {{{0, 0}, {0, 1}}}};
  auto sq = plan::join_polylines(square, 0.05);
  REQUIRE(sq.size() == 1);
  CHECK(sq[0].pts.front() == sq[0].pts.back());
  CHECK(segments_of(sq) == segments_of(square));
}

TEST_CASE("strokes are ordered with free direction, each exactly once", "[plan][tour]") {
  Rng rng(5);
  Drawing d;
  Layer l;
  for (int i = 0; i < 500; ++i) {
    Vec2 a{rng.uniform() * 100, rng.uniform() * 100};
    Vec2 b{a.x + rng.uniform() * 4 - 2, a.y + rng.uniform() * 4 - 2};
    l.lines.push_back({{a, {a.x + 0.5, a.y + 0.7}, b}});
  }
  for (int i = 0; i < 500; ++i) l.dots.push_back({{rng.uniform() * 100, rng.uniform() * 100}, 0.3});
  d.layers.push_back(l);
  PlanOptions opt;
  opt.join_tolerance_mm = 0;  // random segments: no joins to worry about
  opt.optimize_seconds = 0;
  const Plan greedy = plan_drawing(d, opt);
  opt.optimize_seconds = 30;
  const Plan p = plan_drawing(d, opt);
  REQUIRE(p.layers.size() == 1);
  CHECK(segments_of(p.layers[0].strokes) == segments_of(l.lines));
  size_t touches = 0;
  for (const auto& s : p.layers[0].strokes) touches += s.pts.size() == 1;
  CHECK(touches == 500);
  CHECK(p.layers[0].strokes.size() == 1000);
  CHECK(pen_up_travel(p) < pen_up_travel(greedy));
}

TEST_CASE("plan_drawing keeps layers, pens and every segment", "[plan]") {
  Drawing d;
  for (int k = 0; k < 3; ++k) {
    Layer l;
    l.pen.name = "pen" + std::to_string(k);
    auto pts = random_points(200, 100, 30 + k);
    std::vector<std::pair<uint32_t, uint32_t>> mst;
    for (const auto& e : spatial::euclidean_mst(pts)) mst.push_back({e.a, e.b});
    l.lines = as_segments(pts, mst, k);
    l.dots.push_back({{5, 5}, 0.2});
    l.circles.push_back({{50, 50}, 3, true});
    d.layers.push_back(l);
  }
  d.layers.push_back(Layer{});  // an empty layer stays, so pen numbers stay
  PlanOptions opt;
  const Plan p = plan_drawing(d, opt);
  REQUIRE(p.layers.size() == 4);
  CHECK(p.layers[3].strokes.empty());
  for (int k = 0; k < 3; ++k) {
    CHECK(p.layers[k].pen.name == d.layers[k].pen.name);
    auto drawn = segments_of(p.layers[k].strokes);
    for (const auto& [seg, count] : segments_of(d.layers[k].lines)) CHECK(drawn[seg] == count);
    const size_t odd = odd_vertices(d.layers[k].lines);
    CHECK(p.layers[k].strokes.size() == odd / 2 + 2);  // tree strokes + the dot + the circle
  }
  // A drawing given up plans the same, its primitives freed, its pens kept.
  Drawing given = d;
  const Plan q = plan_drawing(std::move(given), opt);
  REQUIRE(q.layers.size() == p.layers.size());
  for (size_t k = 0; k < p.layers.size(); ++k) {
    REQUIRE(q.layers[k].strokes.size() == p.layers[k].strokes.size());
    for (size_t i = 0; i < p.layers[k].strokes.size(); ++i) CHECK(q.layers[k].strokes[i].pts == p.layers[k].strokes[i].pts);
    CHECK(given.layers[k].primitive_count() == 0);
    CHECK(given.layers[k].pen.name == d.layers[k].pen.name);
  }
}

namespace {
double dist_to_path(Vec2 q, const std::vector<Vec2>& pts) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t k = 1; k < pts.size(); ++k) {
    Vec2 a = pts[k - 1], b = pts[k];
    double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? std::clamp(((q.x - a.x) * dx + (q.y - a.y) * dy) / l2, 0.0, 1.0) : 0;
    best = std::min(best, std::hypot(a.x + t * dx - q.x, a.y + t * dy - q.y));
  }
  return best;
}
}  // namespace

TEST_CASE("circle fills cover the disc and stay inside it", "[plan][fill]") {
  for (auto mode : {plan::FillMode::Spiral, plan::FillMode::Hatch}) {
    for (double r : {0.4, 1.0, 2.7}) {
      plan::FillOptions fo;
      fo.mode = mode;
      fo.pen_width = 0.3;
      const Circle c{{10, 20}, r, true};
      const Stroke s = plan::circle_stroke(c, fo);
      const double R = r - fo.pen_width / 2;
      double worst = 0;
      for (double y = -R; y <= R; y += R / 40)
        for (double x = -R; x <= R; x += R / 40) {
          if (x * x + y * y > R * R) continue;
          worst = std::max(worst, dist_to_path({c.c.x + x, c.c.y + y}, s.pts));
        }
      INFO(plan::to_string(mode) << " r=" << r);
      CHECK(worst <= fo.pen_width / 2 + 1e-9);
      for (const Vec2& p : s.pts) CHECK(std::hypot(p.x - c.c.x, p.y - c.c.y) <= R + 1e-9);
    }
  }
  plan::FillOptions fo;
  fo.pen_width = 0.5;
  CHECK(plan::circle_stroke({{1, 1}, 0.25, true}, fo).pts.size() == 1);  // no wider than the pen: a touch
  fo.mode = plan::FillMode::None;
  const Stroke outline = plan::circle_stroke({{1, 1}, 2, true}, fo);
  for (const Vec2& p : outline.pts) CHECK(std::hypot(p.x - 1, p.y - 1) == Approx(1.75));
  const Stroke ring = plan::circle_stroke({{1, 1}, 2, false}, fo);
  for (const Vec2& p : ring.pts) CHECK(std::hypot(p.x - 1, p.y - 1) == Approx(2.0));
}

TEST_CASE("dots wider than the pen are filled, smaller ones are touches", "[plan][fill]") {
  Drawing d;
  Layer l;
  l.pen.width_mm = 0.3;
  l.dots = {{{10, 10}, 0.3}, {{20, 10}, 1.5}};
  d.layers.push_back(l);
  const Plan p = plan_drawing(d, PlanOptions{});
  REQUIRE(p.layers[0].strokes.size() == 2);
  CHECK(p.layers[0].strokes[0].pts.size() == 1);
  CHECK(p.layers[0].strokes[1].pts.size() > 10);
}

TEST_CASE("many dots and circles become the same strokes on 1 and 3 threads", "[plan][fill][threads]") {
  // Enough of each (dots, circles of no pass, circles of a pass) to be made on threads.
  Rng rng(11);
  Drawing d;
  Layer l;
  l.pen.width_mm = 0.3;
  for (int i = 0; i < 9000; ++i) {
    l.dots.push_back({{rng.uniform() * 200, rng.uniform() * 280}, rng.uniform() * 1.2});
    l.circles.push_back({{rng.uniform() * 200, rng.uniform() * 280}, 0.1 + rng.uniform(), i % 3 != 0, colors::black, i % 2});
  }
  d.layers.push_back(l);
  PlanOptions po;
  po.optimize_effort = 0;
  auto strokes = [&](int threads) {
    set_thread_count(threads);
    const Plan p = plan_drawing(d, po);
    set_thread_count(0);
    std::vector<std::vector<Vec2>> all;
    for (const auto& layer : p.layers)
      for (const auto& s : layer.strokes) all.push_back(s.pts);
    return all;
  };
  const auto one = strokes(1), three = strokes(3);
  REQUIRE(one.size() == 18000);
  bool same = three.size() == one.size();
  for (size_t k = 0; same && k < one.size(); ++k) {
    same = one[k].size() == three[k].size();
    for (size_t i = 0; same && i < one[k].size(); ++i) same = one[k][i].x == three[k][i].x && one[k][i].y == three[k][i].y;
  }
  CHECK(same);
  // A disc too large to fill fails the plan on the threads as on one, in one line.
  d.layers[0].circles[4000] = {{100, 100}, 999, true, colors::black, 0};
  d.layers[0].pen.width_mm = 0.01;
  set_thread_count(3);
  CHECK_THROWS_AS(plan_drawing(d, po), UserError);
  set_thread_count(0);
}

TEST_CASE("plan stats: lengths, lifts and time", "[plan][stats]") {
  Plan p;
  PlannedLayer l;
  l.pen.name = "black";
  l.strokes = {{{{3, 4}}}, {{{6, 8}, {6, 18}}}};
  p.layers.push_back(l);
  MotionParams m;
  const PlanStats st = plan_stats(p, m, {0, 0}, true);
  REQUIRE(st.layers.size() == 1);
  CHECK(st.layers[0].pen_up_mm == Approx(10));
  CHECK(st.layers[0].pen_down_mm == Approx(10));
  CHECK(st.layers[0].pen_lifts == 2);
  CHECK(st.layers[0].touches == 1);
  CHECK(st.home_mm == Approx(std::hypot(6, 18)));
  CHECK(st.total.pen_up_mm == Approx(10 + std::hypot(6, 18)));
  CHECK(st.total.seconds > st.layers[0].seconds);
  CHECK(st.layers[0].seconds > 2 * (m.pen_lift_s + m.pen_drop_s));
  // The lengths alone (for a job whose lines are timed): the same, with no seconds.
  const PlanStats lengths = plan_lengths(p, {0, 0}, true);
  CHECK(lengths.total.pen_up_mm == st.total.pen_up_mm);
  CHECK(lengths.layers[0].pen_down_mm == st.layers[0].pen_down_mm);
  CHECK(lengths.total.pen_lifts == st.total.pen_lifts);
  CHECK(lengths.total.seconds == 0);
  const auto j = to_json(st);
  CHECK(j["total"]["pen_lifts"].get<size_t>() == 2);
  CHECK(j["layers"][0]["pen"] == "black");
}

TEST_CASE("bad planner options are user errors", "[plan]") {
  PlanOptions o;
  o.optimize_seconds = -1;
  CHECK_THROWS_AS(plan_drawing(Drawing{}, o), UserError);
  o.optimize_seconds = std::nan("");
  CHECK_THROWS_AS(o.validate(), UserError);
  CHECK_THROWS_AS(plan::parse_fill_mode("crosshatch"), UserError);
  CHECK(plan::parse_fill_mode("hatch") == plan::FillMode::Hatch);
}

TEST_CASE("non-finite drawings are user errors, not crashes", "[plan]") {
  Drawing d;
  d.layers.resize(1);
  d.layers[0].dots.push_back({{std::nan(""), 1}, 0.3});
  CHECK_THROWS_AS(plan_drawing(d, PlanOptions{}), UserError);
  d.layers[0].dots.clear();
  d.layers[0].circles.push_back({{1, 1}, std::numeric_limits<double>::infinity(), true});
  CHECK_THROWS_AS(plan_drawing(d, PlanOptions{}), UserError);
  d.layers[0].circles.clear();
  d.layers[0].lines.push_back({{{0, 0}, {1, std::nan("")}}});
  CHECK_THROWS_AS(plan_drawing(d, PlanOptions{}), UserError);
  d.layers[0].lines.clear();
  // Finite but far off: once a segfault in the kd-tree, and signed overflow in the vertex grid.
  for (double far : {1.7e308, 1e18, -2e6}) {
    d.layers[0].circles.push_back({{20, far}, 10, false});
    CHECK_THROWS_WITH(plan_drawing(d, PlanOptions{}), Catch::Contains("outside +-1000000 mm"));
    d.layers[0].circles.clear();
    d.layers[0].lines.push_back({{{0, 0}, {far, 1}}});
    CHECK_THROWS_WITH(plan_drawing(d, PlanOptions{}), Catch::Contains("outside +-1000000 mm"));
    d.layers[0].lines.clear();
  }
  d.layers[0].pen.width_mm = 0.01;
  d.layers[0].circles.push_back({{500, 500}, 1000, true});  // millions of passes
  CHECK_THROWS_AS(plan_drawing(d, PlanOptions{}), UserError);
}

TEST_CASE("a pen's circles are drawn pass by pass, each pass one tour", "[plan][passes]") {
  // Pass 1 lies beside the origin, pass 0 far from it: a single tour would start with
  // pass 1; passes keep pass 0 (the ebauche) first, then the dots over it.
  Drawing d;
  Layer l;
  l.pen = Pen{"red", Color{200, 30, 30}, 0.4};
  for (int i = 0; i < 20; ++i) {
    Circle near{{1.0 + i, 1.0}, 0.3, true, l.pen.color};
    near.pass = 1;
    l.circles.push_back(near);
    l.circles.push_back(Circle{{100.0 + i, 100.0}, 0.3, true, l.pen.color});
  }
  d.layers.push_back(l);
  const Plan plan = plan_drawing(d, PlanOptions{});
  REQUIRE(plan.layers.size() == 1);
  const auto& strokes = plan.layers[0].strokes;
  REQUIRE(strokes.size() == 40);
  for (size_t i = 0; i < strokes.size(); ++i) {
    INFO("stroke " << i);
    CHECK((strokes[i].pts.front().x > 50) == (i < 20));  // the far pass 0 first
  }
  // All in pass 0: one tour, which starts at the origin's side.
  for (auto& c : d.layers[0].circles) c.pass = 0;
  CHECK(plan_drawing(d, PlanOptions{}).layers[0].strokes.front().pts.front().x < 50);
}
