// The SVG reader against hand-computed coordinates: every element, every path command
// (absolute and relative), arcs, transforms, units, layers, hidden content, errors, and a
// round trip through stipplot's own SVG writers.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "svg/planned_svg.hpp"
#include "svg/svg_reader.hpp"
#include "svg/svg_writer.hpp"
#include "util/error.hpp"
#include "writers/plan_fixtures.hpp"

using namespace stipplot;

namespace {

// An SVG whose user unit is exactly 1 mm, on a 100 x 100 mm page.
std::string mm_svg(const std::string& body) {
  return R"~(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">)~" + body +
         "</svg>";
}

Drawing parse(const std::string& svg, double tol = 0.05) {
  SvgReadOptions o;
  o.tolerance_mm = tol;
  return parse_svg(svg, "test.svg", o);
}

std::vector<Polyline> all_lines(const Drawing& d) {
  std::vector<Polyline> out;
  for (const auto& l : d.layers)
    for (const auto& p : l.lines) out.push_back(p);
  return out;
}

void check_pts(const Polyline& pl, std::vector<Vec2> want, double eps = 1e-9) {
  REQUIRE(pl.pts.size() == want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    INFO("point " << i);
    CHECK(pl.pts[i].x == Approx(want[i].x).margin(eps));
    CHECK(pl.pts[i].y == Approx(want[i].y).margin(eps));
  }
}

std::string error_of(const std::string& svg) {
  try {
    parse(svg);
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("straight elements: line, polyline, polygon, rect", "[svg]") {
  Drawing d = parse(mm_svg(R"~(<line x1="1" y1="2" x2="3" y2="4" stroke="black"/>
    <polyline points="0,0 10,0 10,10" stroke="black"/>
    <polygon points="20 20, 30 20 25 30" stroke="black"/>
    <rect x="40" y="40" width="10" height="5" stroke="black"/>)~"));
  auto lines = all_lines(d);
  REQUIRE(lines.size() == 4);
  check_pts(lines[0], {{1, 2}, {3, 4}});
  check_pts(lines[1], {{0, 0}, {10, 0}, {10, 10}});
  check_pts(lines[2], {{20, 20}, {30, 20}, {25, 30}, {20, 20}});
  check_pts(lines[3], {{40, 40}, {50, 40}, {50, 45}, {40, 45}, {40, 40}});
  CHECK(d.page.width_mm == 100);
}

TEST_CASE("path commands, absolute and relative, give the same straight geometry", "[svg]") {
  Drawing a = parse(mm_svg(R"~(<path stroke="black" d="M10 10 L20 10 H30 V20 L10 20 Z"/>)~"));
  Drawing r = parse(mm_svg(R"~(<path stroke="black" d="m10,10 l10,0 h10 v10 l-20,0 z"/>)~"));
  Drawing compact = parse(mm_svg(R"~(<path stroke="black" d="M10,10L20,10H30V20L10,20z"/>)~"));
  std::vector<Vec2> want{{10, 10}, {20, 10}, {30, 10}, {30, 20}, {10, 20}, {10, 10}};
  check_pts(all_lines(a).at(0), want);
  check_pts(all_lines(r).at(0), want);
  check_pts(all_lines(compact).at(0), want);
  // implicit lineto after moveto, several subpaths, relative moveto after Z from the start
  Drawing m = parse(mm_svg(R"~(<path stroke="black" d="M0 0 10 0 10 10 Z m5 5 l1 0 M50 50 60 60"/>)~"));
  auto lines = all_lines(m);
  REQUIRE(lines.size() == 3);
  check_pts(lines[0], {{0, 0}, {10, 0}, {10, 10}, {0, 0}});
  check_pts(lines[1], {{5, 5}, {6, 5}});
  check_pts(lines[2], {{50, 50}, {60, 60}});
  // numbers run together as SVG allows
  Drawing n = parse(mm_svg(R"~(<path stroke="black" d="M.5.5L1e1-0.5.25,1.5"/>)~"));
  check_pts(all_lines(n).at(0), {{0.5, 0.5}, {10, -0.5}, {0.25, 1.5}});
}

TEST_CASE("curves are flattened within the tolerance and end exactly on their endpoints", "[svg]") {
  const double tol = 0.01;
  // Cubic: compare every flattened point with the true curve (nearest sample).
  Drawing d = parse(mm_svg(R"~(<path stroke="black" d="M10 80 C 40 10, 65 10, 95 80"/>)~"), tol);
  auto pl = all_lines(d).at(0);
  REQUIRE(pl.pts.size() > 10);
  CHECK(pl.pts.front() == Vec2{10, 80});
  CHECK(pl.pts.back() == Vec2{95, 80});
  auto bez = [](double t) {
    double u = 1 - t;
    return Vec2{u * u * u * 10 + 3 * u * u * t * 40 + 3 * u * t * t * 65 + t * t * t * 95,
                u * u * u * 80 + 3 * u * u * t * 10 + 3 * u * t * t * 10 + t * t * t * 80};
  };
  // every point of the true curve is within tol of the polyline
  auto dist_to_polyline = [&](Vec2 q) {
    double best = 1e9;
    for (size_t i = 0; i + 1 < pl.pts.size(); ++i) {
      Vec2 a = pl.pts[i], b = pl.pts[i + 1];
      double dx = b.x - a.x, dy = b.y - a.y, L = dx * dx + dy * dy;
      double t = L > 0 ? std::clamp(((q.x - a.x) * dx + (q.y - a.y) * dy) / L, 0.0, 1.0) : 0;
      best = std::min(best, std::hypot(q.x - a.x - t * dx, q.y - a.y - t * dy));
    }
    return best;
  };
  for (int i = 0; i <= 1000; ++i) CHECK(dist_to_polyline(bez(i / 1000.0)) <= tol * 1.01);
  // coarser tolerance, fewer points
  Drawing coarse = parse(mm_svg(R"~(<path stroke="black" d="M10 80 C 40 10, 65 10, 95 80"/>)~"), 0.5);
  CHECK(all_lines(coarse).at(0).pts.size() < pl.pts.size());

  // S reflects the previous control point: C then S equals C then the explicit C.
  Drawing s = parse(mm_svg(R"~(<path stroke="black" d="M0 0 C 0 10 10 10 10 0 S 20 -10 20 0"/>)~"));
  Drawing c = parse(mm_svg(R"~(<path stroke="black" d="M0 0 C 0 10 10 10 10 0 C 10 -10 20 -10 20 0"/>)~"));
  check_pts(all_lines(s).at(0), all_lines(c).at(0).pts);
  // relative c/s give the same as absolute
  Drawing rs = parse(mm_svg(R"~(<path stroke="black" d="m0 0 c 0 10 10 10 10 0 s 10 -10 10 0"/>)~"));
  check_pts(all_lines(rs).at(0), all_lines(c).at(0).pts, 1e-9);
  // Q/T: T reflects, and q/t relative agree
  Drawing q = parse(mm_svg(R"~(<path stroke="black" d="M0 0 Q 5 10 10 0 T 20 0"/>)~"));
  Drawing q2 = parse(mm_svg(R"~(<path stroke="black" d="M0 0 Q 5 10 10 0 Q 15 -10 20 0"/>)~"));
  Drawing qr = parse(mm_svg(R"~(<path stroke="black" d="m0 0 q 5 10 10 0 t 10 0"/>)~"));
  check_pts(all_lines(q).at(0), all_lines(q2).at(0).pts);
  check_pts(all_lines(qr).at(0), all_lines(q2).at(0).pts, 1e-9);
  // the quadratic's apex: y = 5 at x = 5 (within tolerance)
  double maxy = 0;
  auto q2_line = all_lines(q2).at(0);
  for (auto p : q2_line.pts)
    if (p.x <= 10) maxy = std::max(maxy, p.y);
  CHECK(maxy == Approx(5).margin(0.05));
}

TEST_CASE("arcs follow the SVG endpoint-to-centre parametrisation", "[svg]") {
  const double tol = 0.01;
  // Half circle of radius 10 from (40,50) to (60,50), centre (50,50); sweep=1 goes through
  // y < 50 (clockwise on screen), sweep=0 through y > 50.
  for (int sweep : {0, 1}) {
    std::string svg = mm_svg("<path stroke=\"black\" d=\"M40 50 A10 10 0 0 " + std::to_string(sweep) + " 60 50\"/>");
    auto pl = all_lines(parse(svg, tol)).at(0);
    CHECK(pl.pts.front() == Vec2{40, 50});
    CHECK(pl.pts.back() == Vec2{60, 50});
    for (auto p : pl.pts) CHECK(std::hypot(p.x - 50, p.y - 50) == Approx(10).margin(1e-9));
    Vec2 mid = pl.pts[pl.pts.size() / 2];
    if (sweep) CHECK(mid.y < 45);
    else CHECK(mid.y > 55);
    // chord error within tolerance: consecutive points close enough
    for (size_t i = 0; i + 1 < pl.pts.size(); ++i) {
      double chord = std::hypot(pl.pts[i + 1].x - pl.pts[i].x, pl.pts[i + 1].y - pl.pts[i].y);
      CHECK(10 - std::sqrt(100 - chord * chord / 4) <= tol * 1.0001);
    }
  }
  // large-arc flag: a quarter vs three quarters of a circle between the same points
  auto small = all_lines(parse(mm_svg(R"~(<path stroke="black" d="M60 50 A10 10 0 0 1 50 60"/>)~"))).at(0);
  auto large = all_lines(parse(mm_svg(R"~(<path stroke="black" d="M60 50 a10 10 0 1 0 -10 10"/>)~"))).at(0);
  auto length = [](const Polyline& p) {
    double s = 0;
    for (size_t i = 0; i + 1 < p.pts.size(); ++i) s += std::hypot(p.pts[i + 1].x - p.pts[i].x, p.pts[i + 1].y - p.pts[i].y);
    return s;
  };
  CHECK(length(small) == Approx(std::numbers::pi * 10 / 2).epsilon(0.003));
  CHECK(length(large) == Approx(3 * std::numbers::pi * 10 / 2).epsilon(0.003));
  for (auto p : large.pts) CHECK(std::hypot(p.x - 50, p.y - 50) == Approx(10).margin(1e-9));
  // rotated ellipse arc: every point satisfies the rotated ellipse equation. Centre
  // (50,50), rx 20, ry 10, rotated 30 degrees; endpoints at parameter angles 0 and 180.
  double phi = 30 * std::numbers::pi / 180, c = std::cos(phi), s = std::sin(phi);
  Vec2 p0{50 + 20 * c, 50 + 20 * s}, p1{50 - 20 * c, 50 - 20 * s};
  char buf[200];
  std::snprintf(buf, sizeof buf, "<path stroke=\"black\" d=\"M%.12f %.12f A20 10 30 0 1 %.12f %.12f\"/>", p0.x, p0.y,
                p1.x, p1.y);
  auto ell = all_lines(parse(mm_svg(buf))).at(0);
  for (auto p : ell.pts) {
    double x = p.x - 50, y = p.y - 50, u = c * x + s * y, v = -s * x + c * y;
    CHECK(u * u / 400 + v * v / 100 == Approx(1).margin(1e-9));
  }
  // radii too small are scaled up: a radius-1 arc between points 20 apart is a half circle of radius 10
  auto grown = all_lines(parse(mm_svg(R"~(<path stroke="black" d="M40 50 A1 1 0 0 1 60 50"/>)~"))).at(0);
  for (auto p : grown.pts) CHECK(std::hypot(p.x - 50, p.y - 50) == Approx(10).margin(1e-6));
  // zero radius: a straight line
  check_pts(all_lines(parse(mm_svg(R"~(<path stroke="black" d="M0 0 A0 5 0 0 1 10 0"/>)~"))).at(0), {{0, 0}, {10, 0}});
}

TEST_CASE("circles, ellipses and rounded rects", "[svg]") {
  Drawing d = parse(mm_svg(R"~(<g stroke="black" fill="none" stroke-width="0.5">
      <circle cx="50" cy="50" r="10"/>
      <circle cx="10" cy="10" r="0.2" fill="black" stroke="none"/>
      <circle cx="20" cy="20" r="3" fill="#ff0000" stroke="none"/>
      <ellipse cx="50" cy="50" rx="20" ry="10"/>
      <rect x="10" y="60" width="30" height="20" rx="5"/>
    </g>)~"));
  REQUIRE(d.layers.size() == 2);  // outside Inkscape layers: by stroke colour, else fill colour
  const Layer& l = d.layers[0];
  CHECK(l.pen.width_mm == Approx(0.5));
  REQUIRE(l.circles.size() == 1);
  CHECK(l.circles[0].c == Vec2{50, 50});
  CHECK(l.circles[0].r == 10);
  CHECK_FALSE(l.circles[0].filled);
  REQUIRE(d.layers[1].circles.size() == 1);
  CHECK(d.layers[1].pen.color == Color{255, 0, 0});
  CHECK(d.layers[1].circles[0].filled);
  CHECK(d.layers[1].circles[0].r == 3);
  CHECK(d.layers[1].circles[0].fill == Color{255, 0, 0});
  REQUIRE(l.dots.size() == 1);  // filled, unstroked, no wider than the stroke width
  CHECK(l.dots[0].c == Vec2{10, 10});
  CHECK(l.dots[0].diameter == Approx(0.4));
  REQUIRE(l.lines.size() == 2);
  for (auto p : l.lines[0].pts) {
    double u = (p.x - 50) / 20, v = (p.y - 50) / 10;
    CHECK(u * u + v * v == Approx(1).margin(1e-9));
  }
  CHECK(l.lines[0].pts.front() == l.lines[0].pts.back());
  // rounded rect: inside its box, corners cut, closed
  const auto& rr = l.lines[1].pts;
  CHECK(rr.front() == rr.back());
  for (auto p : rr) {
    CHECK(p.x >= 10 - 1e-9);
    CHECK(p.x <= 40 + 1e-9);
    CHECK(p.y >= 60 - 1e-9);
    CHECK(p.y <= 80 + 1e-9);
    CHECK_FALSE((p.x < 11 && p.y < 61));  // the corner itself is not on the outline
  }
  // a circle under a non-uniform scale is an ellipse polyline
  Drawing s = parse(mm_svg(R"~(<circle cx="0" cy="0" r="10" stroke="black" fill="none" transform="translate(50 50) scale(2 1)"/>)~"));
  REQUIRE(s.layers.at(0).circles.empty());
  for (auto p : s.layers[0].lines.at(0).pts) {
    double u = (p.x - 50) / 20, v = (p.y - 50) / 10;
    CHECK(u * u + v * v == Approx(1).margin(1e-9));
  }
}

TEST_CASE("nested transforms compose in document order", "[svg]") {
  Drawing d = parse(mm_svg(R"~(
    <g transform="translate(10,20)">
      <g transform="rotate(90)">
        <line x1="0" y1="0" x2="5" y2="0" stroke="black"/>
      </g>
      <line x1="0" y1="0" x2="1" y2="1" stroke="black" transform="scale(2) translate(1 1)"/>
      <line x1="0" y1="0" x2="10" y2="0" stroke="black" transform="rotate(180, 5, 0)"/>
      <line x1="0" y1="0" x2="0" y2="10" stroke="black" transform="skewX(45)"/>
      <line x1="0" y1="0" x2="10" y2="0" stroke="black" transform="skewY(45)"/>
      <line x1="1" y1="1" x2="2" y2="2" stroke="black" transform="matrix(1 0 0 -1 0 0)"/>
    </g>)~"));
  auto lines = all_lines(d);
  REQUIRE(lines.size() == 6);
  check_pts(lines[0], {{10, 20}, {10, 25}}, 1e-9);
  check_pts(lines[1], {{12, 22}, {14, 24}}, 1e-9);
  check_pts(lines[2], {{20, 20}, {10, 20}}, 1e-9);
  check_pts(lines[3], {{10, 20}, {20, 30}}, 1e-9);
  check_pts(lines[4], {{10, 20}, {20, 30}}, 1e-9);
  check_pts(lines[5], {{11, 19}, {12, 18}}, 1e-9);
}

TEST_CASE("units: width/height with viewBox, px at 96 per inch, in, cm, pt", "[svg]") {
  // 2in x 1in page with a viewBox of 200 x 100: one user unit = 0.254 mm
  Drawing d = parse(R"~(<svg xmlns="http://www.w3.org/2000/svg" width="2in" height="1in" viewBox="0 0 200 100">
    <line x1="0" y1="0" x2="100" y2="50" stroke="black"/></svg>)~");
  CHECK(d.page.width_mm == Approx(50.8));
  CHECK(d.page.height_mm == Approx(25.4));
  check_pts(all_lines(d).at(0), {{0, 0}, {25.4, 12.7}}, 1e-9);
  // no viewBox: user units are px (96 per inch)
  Drawing px = parse(R"~(<svg xmlns="http://www.w3.org/2000/svg" width="960" height="480">
    <line x1="96" y1="0" x2="192" y2="0" stroke="black"/></svg>)~");
  CHECK(px.page.width_mm == Approx(254));
  check_pts(all_lines(px).at(0), {{25.4, 0}, {50.8, 0}}, 1e-9);
  // viewBox with an offset, cm and pt units
  Drawing cm = parse(R"~(<svg xmlns="http://www.w3.org/2000/svg" width="10cm" height="72pt" viewBox="10 10 100 25.4">
    <line x1="10" y1="10" x2="110" y2="35.4" stroke="black"/></svg>)~");
  CHECK(cm.page.width_mm == Approx(100));
  CHECK(cm.page.height_mm == Approx(25.4));
  check_pts(all_lines(cm).at(0), {{0, 0}, {100, 25.4}}, 1e-9);
  // meet: a square viewBox on a wide page is centred
  Drawing meet = parse(R"~(<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="100mm" viewBox="0 0 10 10">
    <line x1="0" y1="0" x2="10" y2="10" stroke="black"/></svg>)~");
  check_pts(all_lines(meet).at(0), {{50, 0}, {150, 100}}, 1e-9);
  Drawing none = parse(R"~(<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="100mm" viewBox="0 0 10 10" preserveAspectRatio="none">
    <line x1="0" y1="0" x2="10" y2="10" stroke="black"/></svg>)~");
  check_pts(all_lines(none).at(0), {{0, 0}, {200, 100}}, 1e-9);
}

TEST_CASE("Inkscape layers become pens by label, others by stroke colour, hidden content skipped", "[svg]") {
  Drawing d = parse(mm_svg(R"~(
    <g inkscape:groupmode="layer" inkscape:label="1 red pen" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape">
      <line x1="0" y1="0" x2="1" y2="0" stroke="#ff0000" stroke-width="0.4"/>
      <g><line x1="0" y1="1" x2="1" y2="1" stroke="#00ff00"/></g>
    </g>
    <g inkscape:groupmode="layer" inkscape:label="% notes" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape">
      <line x1="0" y1="0" x2="1" y2="0" stroke="black"/>
    </g>
    <g inkscape:groupmode="layer" inkscape:label="hidden" style="display:none" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape">
      <line x1="0" y1="0" x2="1" y2="0" stroke="black"/>
    </g>
    <line x1="0" y1="5" x2="1" y2="5" style="stroke:#0000ff;stroke-width:0.7"/>
    <line x1="0" y1="6" x2="1" y2="6" stroke="blue"/>
    <line x1="0" y1="7" x2="1" y2="7" stroke="blue" visibility="hidden"/>
    <path d="M0 8 L1 8" fill="#00ff00"/>
    <defs><line x1="0" y1="0" x2="1" y2="0" stroke="black"/></defs>)~"));
  REQUIRE(d.layers.size() == 3);
  CHECK(d.layers[0].pen.name == "red pen");
  CHECK(d.layers[0].pen.color == Color{255, 0, 0});
  CHECK(d.layers[0].pen.width_mm == Approx(0.4));
  CHECK(d.layers[0].lines.size() == 2);  // both lines of the layer, whatever their colour
  CHECK(d.layers[1].pen.color == Color{0, 0, 255});
  CHECK(d.layers[1].pen.width_mm == Approx(0.7));
  CHECK(d.layers[1].lines.size() == 2);
  CHECK(d.layers[2].pen.color == Color{0, 255, 0});  // unstroked: by fill
  CHECK(d.layers[2].lines.size() == 1);
}

TEST_CASE("malformed SVG names the element and the line", "[svg]") {
  std::string e = error_of("<svg xmlns=\"http://www.w3.org/2000/svg\">\n<g>\n<line x1='1'\n</svg>");
  CHECK(e.find("test.svg line") != std::string::npos);
  CHECK(e.find("malformed XML") != std::string::npos);

  e = error_of("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10mm\" height=\"10mm\">\n\n<path d=\"M 0 0 L 1 x\"/>\n</svg>");
  CHECK(e.find("test.svg line 3: <path> d:") != std::string::npos);

  e = error_of(mm_svg("\n<path d=\"L 1 1\"/>"));
  CHECK(e.find("line 2: <path> d: path data must start with M") != std::string::npos);

  e = error_of(mm_svg("\n\n<path d=\"M0 0 A 1 1 0 2 1 5 5\"/>"));
  CHECK(e.find("line 3: <path> d: arc large-arc flag") != std::string::npos);

  e = error_of(mm_svg("\n<circle cx=\"abc\" r=\"1\"/>"));
  CHECK(e.find("line 2: <circle> cx=\"abc\"") != std::string::npos);

  e = error_of(mm_svg("\n<g transform=\"rotate(1,2)\"><line x2=\"1\"/></g>"));
  CHECK(e.find("line 2: <g> transform=\"rotate(1,2)\"") != std::string::npos);

  e = error_of(mm_svg("\n<g transform=\"wobble(3)\"/>"));
  CHECK(e.find("unknown function 'wobble'") != std::string::npos);

  e = error_of(mm_svg("<polyline points=\"1 2 3\"/>"));
  CHECK(e.find("<polyline> points: odd number") != std::string::npos);

  e = error_of(mm_svg("<line x2=\"1\" stroke=\"notacolour\"/>"));
  CHECK(e.find("<line> stroke: not a colour") != std::string::npos);

  e = error_of("<html></html>");
  CHECK(e.find("not an SVG") != std::string::npos);

  CHECK_THROWS_AS(read_svg("/nonexistent/file.svg"), UserError);
}

TEST_CASE("round trip: Drawing -> svg_writer -> svg_reader keeps coordinates and layers", "[svg]") {
  Drawing d;
  d.page = {297, 210};
  Layer black;
  black.pen = {"black", colors::black, 0.3};
  black.dots = {{{10.5, 20.25}, 0.3}, {{100, 100}, 0.2}};
  black.lines = {{{{1, 2}, {3.125, 4}, {50, 60}}}};
  black.circles = {{{150, 100}, 12.5, false, colors::black}};
  Layer red;
  red.pen = {"red", Color{255, 0, 0}, 0.5};
  red.lines = {{{{200, 10}, {210, 20}}}};
  red.circles = {{{50, 150}, 4, true, Color{255, 0, 0}}};
  d.layers = {black, red};

  Drawing back = parse_svg(svg_string(d), "roundtrip.svg");
  CHECK(back.page.width_mm == Approx(297));
  CHECK(back.page.height_mm == Approx(210));
  REQUIRE(back.layers.size() == 2);
  for (size_t i = 0; i < 2; ++i) {
    const Layer& a = d.layers[i];
    const Layer& b = back.layers[i];
    CHECK(b.pen.name == a.pen.name);
    CHECK(b.pen.color == a.pen.color);
    CHECK(b.pen.width_mm == Approx(a.pen.width_mm));
    REQUIRE(b.dots.size() == a.dots.size());
    for (size_t k = 0; k < a.dots.size(); ++k) {
      CHECK(b.dots[k].c.x == Approx(a.dots[k].c.x).margin(1e-3));
      CHECK(b.dots[k].c.y == Approx(a.dots[k].c.y).margin(1e-3));
      CHECK(b.dots[k].diameter == Approx(a.dots[k].diameter).margin(1e-3));
    }
    REQUIRE(b.lines.size() == a.lines.size());
    for (size_t k = 0; k < a.lines.size(); ++k) check_pts(b.lines[k], a.lines[k].pts, 1e-3);
    REQUIRE(b.circles.size() == a.circles.size());
    for (size_t k = 0; k < a.circles.size(); ++k) {
      CHECK(b.circles[k].c == a.circles[k].c);
      CHECK(b.circles[k].r == Approx(a.circles[k].r));
      CHECK(b.circles[k].filled == a.circles[k].filled);
    }
  }
}

TEST_CASE("planned SVG keeps plot order and hides the travel layer", "[svg][writers]") {
  Plan plan = fixtures::random_plan(4, 2, 30, 10);
  PlannedSvgOptions o;
  o.show_travel = true;
  std::string svg = planned_svg_string(plan, o);
  CHECK(svg.find("style=\"display:none\"") != std::string::npos);
  Drawing back = parse_svg(svg, "planned.svg");
  REQUIRE(back.layers.size() == 2);  // the travel layer is not read as something to plot
  for (size_t li = 0; li < 2; ++li) {
    // single-point strokes came back as dots, the others as polylines, each in plot order
    std::vector<Vec2> dots, firsts;
    for (const auto& s : plan.layers[li].strokes) (s.pts.size() == 1 ? dots : firsts).push_back(s.pts[0]);
    REQUIRE(back.layers[li].dots.size() == dots.size());
    REQUIRE(back.layers[li].lines.size() == firsts.size());
    for (size_t k = 0; k < dots.size(); ++k) {
      CHECK(back.layers[li].dots[k].c.x == Approx(dots[k].x).margin(1e-3));
      CHECK(back.layers[li].dots[k].c.y == Approx(dots[k].y).margin(1e-3));
    }
    for (size_t k = 0; k < firsts.size(); ++k) CHECK(back.layers[li].lines[k].pts[0].x == Approx(firsts[k].x).margin(1e-3));
  }
}

TEST_CASE("<use> draws the referenced element or symbol where it is used", "[svg]") {
  Drawing d = parse(mm_svg(R"~(<defs><line id="l" x1="0" y1="0" x2="1" y2="0" stroke="black"/>
      <symbol id="s"><line x1="0" y1="0" x2="0" y2="2" stroke="black"/></symbol></defs>
      <use href="#l" x="10" y="20"/>
      <g transform="translate(5 5)"><use xlink:href="#s" x="1" y="1"/></g>)~"));
  auto lines = all_lines(d);
  REQUIRE(lines.size() == 2);
  check_pts(lines[0], {{10, 20}, {11, 20}});
  check_pts(lines[1], {{6, 6}, {6, 8}});
  CHECK(error_of(mm_svg("<use href=\"#nothing\"/>")).find("names no element") != std::string::npos);
  CHECK(error_of(mm_svg("<g id=\"a\"><use href=\"#a\"/></g>")).find("cycle") != std::string::npos);
}
