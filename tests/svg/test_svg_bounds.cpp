// The SVG reader's bounds: every number finite and on a page no wider than a km, every
// transform a sane map, and the work an input can ask for capped before it is done.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>

#include "svg/svg_reader.hpp"
#include "test_util.hpp"
#include "util/error.hpp"

using namespace stipplot;

namespace {
std::string crash_input(const char* name) {
  return std::string(STIPPLOT_SOURCE_DIR) + "/tests/fuzz/crashes/svg/" + name;
}
std::string svg_with(const std::string& body) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"100mm\" height=\"100mm\" viewBox=\"0 0 100 100\">" + body +
         "</svg>";
}
// At the finest tolerance export takes (--tolerance 0.0001).
double seconds_to_fail(const std::string& file, const char* expect) {
  SvgReadOptions finest;
  finest.tolerance_mm = 1e-4;
  const auto t0 = std::chrono::steady_clock::now();
  CHECK_THROWS_WITH(read_svg(file, finest), Catch::Contains(expect));
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

TEST_CASE("points far off the page and broken transforms are refused", "[svg][bad-input]") {
  CHECK_THROWS_WITH(read_svg(crash_input("far-circle.svg")), Catch::Contains("outside +-1000000 mm"));
  CHECK_THROWS_WITH(read_svg(crash_input("coordinates-1e18.svg")), Catch::Contains("outside +-1000000 mm"));
  CHECK_THROWS_WITH(read_svg(crash_input("inf-matrix.svg")), Catch::Contains("transform makes a map"));
  CHECK_THROWS_WITH(parse_svg(svg_with("<g transform=\"translate(2e6 0)\"><path d=\"M0 0 L1 1\" stroke=\"black\"/></g>"), "t"),
                    Catch::Contains("transform"));
  CHECK_THROWS_WITH(parse_svg(svg_with("<path d=\"M0 0 L1e7 1\" stroke=\"black\"/>"), "t"),
                    Catch::Contains("<path> has a point outside"));
}

TEST_CASE("rotate and skew by huge angles are rotations, not NaN", "[svg]") {
  Drawing d = read_svg(crash_input("rotate-1e308.svg"));
  REQUIRE(d.layers.size() == 1);
  for (const auto& l : d.layers[0].lines)
    for (const Vec2& p : l.pts) CHECK((std::isfinite(p.x) && std::isfinite(p.y)));
  // rotate(a) is rotate(a mod 360): 720 + 90 turns x into y.
  Drawing r = parse_svg(svg_with("<g transform=\"rotate(810)\"><path d=\"M10 0 L20 0\" stroke=\"black\"/></g>"), "t");
  REQUIRE(r.layers.size() == 1);
  CHECK(r.layers[0].lines[0].pts[0].x == Approx(0).margin(1e-9));
  CHECK(r.layers[0].lines[0].pts[0].y == Approx(10));
}

TEST_CASE("nested <use>, arcs and curves cannot ask for unbounded work", "[svg][bad-input]") {
  // Each once grew memory without end (10^15 <use> copies) or to gigabytes (flattening).
  CHECK(seconds_to_fail(crash_input("use-bomb.svg"), "more than 1000000 elements drawn through <use>") < 60);
  CHECK(seconds_to_fail(crash_input("huge-arcs.svg"), "more than 10000000 points") < 30);
  CHECK(seconds_to_fail(crash_input("deep-curves.svg"), "more than 10000000 points") < 30);
  // The caps are options, and the count is exact: a <use> of a group of two paths draws
  // 3 elements through <use>, and the document's own elements do not count.
  SvgReadOptions o;
  o.max_use_copies = 3;
  const std::string three = svg_with(
      "<defs><g id=\"g\"><path d=\"M0 0 L1 1\" stroke=\"black\"/><path d=\"M0 0 L2 1\" stroke=\"black\"/></g></defs>"
      "<use href=\"#g\"/><path d=\"M0 0 L3 1\" stroke=\"black\"/><path d=\"M0 0 L4 1\" stroke=\"black\"/>");
  CHECK(parse_svg(three, "t", o).primitive_count() == 4);
  o.max_use_copies = 2;
  CHECK_THROWS_WITH(parse_svg(three, "t", o), Catch::Contains("more than 2 elements drawn through <use>"));
  SvgReadOptions p;
  p.max_points = 8;
  CHECK(parse_svg(three, "t", p).primitive_count() == 4);
  p.max_points = 7;
  CHECK_THROWS_WITH(parse_svg(three, "t", p), Catch::Contains("more than 7 points"));
}
