// Hatch fills of areas (holes, fill rules, coverage), the path operations (simplify,
// multipass, reloop, length filter) and layers merged on one pen.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "plan/hatch.hpp"
#include "plan/path_ops.hpp"
#include "plan/planner.hpp"
#include "util/error.hpp"
#include "util/rng.hpp"

using namespace stipplot;
using namespace stipplot::plan;

namespace {

Polyline square(double x0, double y0, double x1, double y1, bool clockwise = true) {
  if (clockwise) return {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}}};
  return {{{x0, y0}, {x0, y1}, {x1, y1}, {x1, y0}, {x0, y0}}};
}

double segment_distance(Vec2 p, Vec2 a, Vec2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
  const double t = l2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / l2, 0.0, 1.0) : 0;
  return std::hypot(a.x + t * dx - p.x, a.y + t * dy - p.y);
}

double distance_to(const std::vector<Stroke>& strokes, Vec2 p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& s : strokes)
    for (size_t k = 1; k < s.pts.size(); ++k) best = std::min(best, segment_distance(p, s.pts[k - 1], s.pts[k]));
  return best;
}

bool inside_square(Vec2 p, double x0, double y0, double x1, double y1, double eps = 1e-9) {
  return p.x >= x0 - eps && p.x <= x1 + eps && p.y >= y0 - eps && p.y <= y1 + eps;
}

}  // namespace

TEST_CASE("hatching covers the area at the spacing and leaves its hole empty", "[plan][hatch]") {
  Area a;
  a.rings = {square(0, 0, 10, 10), square(4, 4, 6, 6, false)};
  for (FillRule rule : {FillRule::nonzero, FillRule::evenodd}) {
    a.rule = rule;
    for (double angle : {0.0, 45.0, 90.0, 30.0}) {
      HatchOptions o;
      o.spacing_mm = 0.5;
      o.angle_degrees = angle;
      o.outline = false;
      const auto strokes = hatch_area(a, o);
      INFO("angle " << angle);
      REQUIRE_FALSE(strokes.empty());
      // every hatch segment runs inside the square, off the hole (connectors hug the edges)
      for (const auto& s : strokes)
        for (size_t k = 1; k < s.pts.size(); ++k) {
          const Vec2 m{(s.pts[k - 1].x + s.pts[k].x) / 2, (s.pts[k - 1].y + s.pts[k].y) / 2};
          CHECK(inside_square(m, 0, 0, 10, 10));
          CHECK_FALSE(inside_square(m, 4.01, 4.01, 5.99, 5.99, 0));
        }
      // every point of the area is within half a spacing of a hatch line
      double worst = 0;
      for (double x = 0.3; x < 9.75; x += 0.37)
        for (double y = 0.3; y < 9.75; y += 0.41) {
          if (inside_square({x, y}, 3.7, 3.7, 6.3, 6.3, 0)) continue;
          worst = std::max(worst, distance_to(strokes, {x, y}));
        }
      CHECK(worst <= 0.25 + 1e-6);
    }
  }
}

TEST_CASE("fill rules differ where rings overlap running the same way", "[plan][hatch]") {
  Area a;
  a.rings = {square(0, 0, 10, 10), square(4, 4, 6, 6)};  // same direction: winding 2 inside the small one
  HatchOptions o;
  o.spacing_mm = 0.5;
  o.angle_degrees = 0;
  o.outline = false;
  a.rule = FillRule::nonzero;
  CHECK(distance_to(hatch_area(a, o), {5, 5}) <= 0.25 + 1e-9);  // filled
  a.rule = FillRule::evenodd;
  CHECK(distance_to(hatch_area(a, o), {5, 5}) > 0.7);  // a hole
}

TEST_CASE("a convex area hatches as one zigzag, outlined when asked", "[plan][hatch]") {
  Area a;
  a.rings = {square(0, 0, 20, 10)};
  HatchOptions o;
  o.spacing_mm = 0.4;
  o.angle_degrees = 0;
  o.outline = false;
  auto strokes = hatch_area(a, o);
  CHECK(strokes.size() == 1);
  CHECK(strokes[0].pts.size() == 2 * 25);  // 10 / 0.4 = 25 lines, both ends of each
  o.outline = true;
  CHECK(hatch_area(a, o).size() == 2);
  o.spacing_mm = 1e-9;
  CHECK_THROWS_AS(hatch_area(a, o), UserError);
}

TEST_CASE("simplify stays within the tolerance and keeps the ends", "[plan][paths]") {
  Rng rng(7);
  Stroke s;
  for (int i = 0; i <= 400; ++i) s.pts.push_back({i * 0.05, std::sin(i * 0.05) * 3 + (rng.uniform() - 0.5) * 0.01});
  const Stroke original = s;
  simplify_stroke(s, 0.05);
  CHECK(s.pts.size() < original.pts.size() / 4);
  CHECK(s.pts.front() == original.pts.front());
  CHECK(s.pts.back() == original.pts.back());
  for (const Vec2& p : original.pts) CHECK(distance_to({s}, p) <= 0.05 + 1e-12);
}

TEST_CASE("multipass goes back and forth on open strokes and round again on closed ones", "[plan][paths]") {
  Stroke open{{{0, 0}, {1, 0}, {2, 0}}};
  multipass_stroke(open, 3);
  CHECK(open.pts == std::vector<Vec2>{{0, 0}, {1, 0}, {2, 0}, {1, 0}, {0, 0}, {1, 0}, {2, 0}});
  Stroke ring = {square(0, 0, 1, 1).pts};
  multipass_stroke(ring, 2);
  CHECK(ring.pts.size() == 9);
  CHECK(ring.pts[5] == Vec2{1, 0});  // the second round starts as the first did
  CHECK(stroke_length(ring) == Approx(8));
}

TEST_CASE("reloop starts a closed stroke at the vertex nearest the pen's way", "[plan][paths]") {
  std::vector<Stroke> strokes{{square(10, 10, 20, 20).pts}, {{{15, 40}, {25, 40}}}};
  reloop_strokes(strokes, {0, 20});
  // from (0, 20) to the square, then on to (15, 40): (10, 20) costs 10 + 20.6, the others 40 or more
  CHECK(strokes[0].pts.front() == Vec2{10, 20});
  CHECK(strokes[0].pts.back() == Vec2{10, 20});
  CHECK(stroke_length(strokes[0]) == Approx(40));
}

TEST_CASE("the planner merges layers on one pen, filters short strokes and applies passes", "[plan][paths]") {
  Drawing d;
  for (int i = 0; i < 3; ++i) {
    Layer l;
    l.pen.name = "p" + std::to_string(i);
    l.pen.number = i == 2 ? 1 : i + 1;  // layers 1 and 3 share pen 1
    l.lines.push_back({{{10.0 * i, 0}, {10.0 * i + 5, 0}}});
    l.lines.push_back({{{10.0 * i, 5}, {10.0 * i + 0.2, 5}}});  // 0.2 mm: filtered below
    d.layers.push_back(l);
  }
  PlanOptions o;
  o.min_length_mm = 0.5;
  o.passes = 2;
  const Plan p = plan_drawing(d, o);
  REQUIRE(p.layers.size() == 2);
  CHECK(p.layers[0].pen.number == 1);
  CHECK(p.layers[0].pen.name == "p0+p2");
  CHECK(p.layers[0].strokes.size() == 2);
  CHECK(p.layers[1].strokes.size() == 1);
  for (const auto& l : p.layers)
    for (const auto& s : l.strokes) CHECK(stroke_length(s) == Approx(10));  // 5 mm, there and back
  o.passes = 0;
  CHECK_THROWS_AS(plan_drawing(d, o), UserError);
}

TEST_CASE("areas are hatched at the pen width by the planner, and left to their outlines with --fill none", "[plan][hatch]") {
  Drawing d;
  Layer l;
  l.pen.width_mm = 0.5;
  Area a;
  a.rings = {square(0, 0, 9, 9)};
  l.areas.push_back(a);
  d.layers.push_back(l);
  PlanOptions o;
  o.hatch_angle_degrees = 0;
  Plan p = plan_drawing(d, o);
  REQUIRE(p.layers[0].strokes.size() == 1);
  CHECK(p.layers[0].strokes[0].pts.size() == 2 * 20);  // 9 / (0.9 x 0.5) = 20 lines
  o.fill = FillMode::None;
  d.layers[0].lines.push_back(a.rings[0]);  // the outline, as the SVG reader gives it
  p = plan_drawing(d, o);
  REQUIRE(p.layers[0].strokes.size() == 1);
  CHECK(p.layers[0].strokes[0].pts.size() == 5);  // the ring alone
}
