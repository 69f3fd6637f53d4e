// Layout: rotation to the sheet, fit, scale, alignment, crop and clipping; layers and pens.
#include <catch2/catch.hpp>
#include <cmath>

#include "layout/layers.hpp"
#include "layout/layout.hpp"
#include "util/error.hpp"

using namespace stipplot;
using namespace stipplot::layout;

namespace {

Drawing page_with(double w, double h) {
  Drawing d;
  d.page.width_mm = w;
  d.page.height_mm = h;
  d.layers.emplace_back();
  return d;
}

Page sheet(double w, double h) {
  Page p;
  p.width_mm = w;
  p.height_mm = h;
  return p;
}

// Every point of every polyline of the drawing, in order.
std::vector<Vec2> points_of(const Drawing& d) {
  std::vector<Vec2> out;
  for (const auto& l : d.layers)
    for (const auto& pl : l.lines) out.insert(out.end(), pl.pts.begin(), pl.pts.end());
  return out;
}

}  // namespace

TEST_CASE("layout turns a portrait drawing onto a landscape sheet, corner to corner", "[layout]") {
  Drawing d = page_with(210, 297);
  d.layers[0].lines.push_back({{{0, 0}, {210, 0}, {210, 297}}});
  d.layers[0].circles.push_back({{50, 100}, 5, false});
  LayoutOptions o;
  o.sheet = sheet(297, 210);
  LayoutReport rep;
  const Drawing out = lay_out(d, o, &rep);
  CHECK(rep.auto_rotated);
  CHECK(rep.rotated_degrees == -90);
  CHECK(out.page.width_mm == 297);
  CHECK(out.page.height_mm == 210);
  // counter-clockwise: (x, y) -> (y, 210 - x); the page's top edge becomes its left edge
  const auto p = points_of(out);
  REQUIRE(p.size() == 3);
  CHECK(p[0] == Vec2{0, 210});
  CHECK(p[1] == Vec2{0, 0});
  CHECK(p[2] == Vec2{297, 0});
  CHECK(out.layers[0].circles[0].c.x == Approx(100));
  CHECK(out.layers[0].circles[0].c.y == Approx(160));
  CHECK(rep.clipped.total() == 0);
  // off with auto_rotate, or by an explicit angle
  o.auto_rotate = false;
  LayoutReport kept;
  const Drawing upright = lay_out(d, o, &kept);
  CHECK_FALSE(kept.auto_rotated);
  CHECK(points_of(upright)[0] == Vec2{0, 0});
}

TEST_CASE("fit scales the ink into the sheet less margins and reach, keeping its aspect, centred", "[layout]") {
  Drawing d = page_with(100, 100);
  d.layers[0].lines.push_back({{{10, 20}, {30, 20}, {30, 60}}});  // ink box 20 x 40
  LayoutOptions o;
  o.sheet = sheet(200, 100);
  o.margin_mm = 5;
  o.fit = true;
  LayoutReport rep;
  // fitting, the ink's own orientation counts: tall ink on a wide sheet is turned, 40 x 20 -> k = 4.5
  Drawing turned = lay_out(d, o, &rep);
  CHECK(rep.auto_rotated);
  CHECK(rep.scale == Approx(4.5));
  o.auto_rotate = false;
  Drawing out = lay_out(d, o, &rep);
  // area 190 x 90: height-limited, k = 90 / 40 = 2.25, ink 45 x 90 centred at x = 100
  CHECK(rep.scale == Approx(2.25));
  auto p = points_of(out);
  CHECK(p[0].x == Approx(77.5));
  CHECK(p[0].y == Approx(5));
  CHECK(p[2].x == Approx(122.5));
  CHECK(p[2].y == Approx(95));
  // the device's reach narrows the area: a reach starting at y = 20 leaves 75 mm
  o.reach = Rect{0, 20, 200, 100};
  out = lay_out(d, o, &rep);
  p = points_of(out);
  CHECK(rep.scale == Approx(75.0 / 40));
  CHECK(p[0].y == Approx(20));
  CHECK(p[2].y == Approx(95));
  // alignment inside the area
  o.reach.reset();
  o.align = Align::bottom_right;
  out = lay_out(d, o, &rep);
  p = points_of(out);
  CHECK(p[2].x == Approx(195));
  CHECK(p[2].y == Approx(95));
}

TEST_CASE("scale and align without fit, and an explicit rotation turns the ink, not the sheet", "[layout]") {
  Drawing d = page_with(100, 100);
  d.layers[0].lines.push_back({{{10, 10}, {20, 10}}});
  d.layers[0].dots.push_back({{10, 10}, 0.4});
  LayoutOptions o;
  o.sheet = sheet(100, 100);
  o.scale = 2;
  LayoutReport rep;
  Drawing out = lay_out(d, o, &rep);
  CHECK(points_of(out)[1] == Vec2{40, 20});
  CHECK(out.layers[0].dots[0].diameter == Approx(0.8));
  o.scale = 1;
  o.align = Align::center;
  out = lay_out(d, o, &rep);
  // the ink is the line and the dot's disc: 9.8..20 x 9.8..10.2, centred on the sheet
  CHECK(points_of(out)[0].x == Approx(45.1));
  CHECK(points_of(out)[0].y == Approx(50));
  o.align.reset();
  o.rotate_degrees = 90;  // clockwise: (x, y) -> (100 - y, x) on a square page
  out = lay_out(d, o, &rep);
  CHECK(points_of(out)[1].x == Approx(90));
  CHECK(points_of(out)[1].y == Approx(20));
  CHECK_FALSE(rep.auto_rotated);
  o.fit = true;
  o.scale = 3;
  CHECK_THROWS_AS(lay_out(d, o), UserError);
}

TEST_CASE("clipping cuts strokes at the sheet's edge and drops what lies off it", "[layout][clip]") {
  Drawing d = page_with(100, 100);
  Layer& l = d.layers[0];
  l.lines.push_back({{{50, 50}, {150, 50}}});                     // cut at x = 100
  l.lines.push_back({{{-10, 10}, {50, 10}, {110, 10}}});          // cut at both ends
  l.lines.push_back({{{120, 120}, {130, 130}}});                  // wholly off: dropped
  l.lines.push_back({{{90, 20}, {110, 20}, {110, 30}, {90, 30}, {90, 20}}});  // closed, seam inside: one stroke
  l.dots.push_back({{99.9, 50}, 0.3});                            // a pen touch on the sheet stays
  l.dots.push_back({{100.2, 50}, 0.3});                           // centre off: dropped
  l.circles.push_back({{50, 50}, 10, false});                     // inside: stays a circle
  l.circles.push_back({{200, 50}, 10, false});                    // off: dropped
  l.circles.push_back({{100, 80}, 10, false});                    // crossing, outline: an arc
  l.circles.push_back({{0, 80}, 10, true});                       // crossing, filled: an area
  LayoutOptions o;
  o.sheet = sheet(100, 100);
  LayoutReport rep;
  const Drawing out = lay_out(d, o, &rep);
  const Layer& c = out.layers[0];
  CHECK(rep.clipped.dropped == 3);
  CHECK(rep.clipped.cut == 5);
  REQUIRE(c.lines.size() == 5);  // two cut lines, the ring, the outlined circle's arc and the filled one's edge
  CHECK(c.lines[0].pts.back() == Vec2{100, 50});
  CHECK(c.lines[1].pts.front() == Vec2{0, 10});
  CHECK(c.lines[1].pts.back() == Vec2{100, 10});
  CHECK(c.lines[2].pts.front() == Vec2{100, 30});  // rejoined round its seam: 100,30 -> 90,30 -> 90,20 -> 100,20
  CHECK(c.lines[2].pts.back() == Vec2{100, 20});
  for (const auto& pl : c.lines)
    for (const auto& p : pl.pts) CHECK((p.x >= 0 && p.x <= 100 + 1e-9 && p.y >= 0 && p.y <= 100));
  CHECK(c.dots.size() == 1);
  CHECK(c.circles.size() == 1);
  REQUIRE(c.areas.size() == 1);
  for (const auto& p : c.areas[0].rings[0].pts) CHECK(p.x >= -1e-9);
}

TEST_CASE("a stroke wholly on the sheet is kept exactly as it was: edges and repeated points and all", "[layout][clip]") {
  Drawing d = page_with(100, 100);
  const Polyline on = {{{0, 0}, {0, 0}, {100, 100}, {50, 100}, {100, 0}, {100, 0}}};
  d.layers[0].lines.push_back(on);
  d.layers[0].lines.push_back({{{50, 50}, {100, 50}, {100.5, 50}}});  // leaves the sheet: cut
  LayoutOptions o;
  o.sheet = sheet(100, 100);
  LayoutReport rep;
  const Drawing out = lay_out(d, o, &rep);
  REQUIRE(out.layers[0].lines.size() == 2);
  CHECK(out.layers[0].lines[0].pts == on.pts);
  CHECK(out.layers[0].lines[1].pts.back() == Vec2{100, 50});
  CHECK(rep.clipped.cut == 1);
  CHECK(rep.clipped.dropped == 0);
}

TEST_CASE("crop keeps a rectangle of the drawing's own page before the layout", "[layout][clip]") {
  Drawing d = page_with(100, 100);
  d.layers[0].lines.push_back({{{0, 50}, {100, 50}}});
  LayoutOptions o;
  o.sheet = sheet(100, 100);
  o.crop = Rect{20, 0, 40, 100};
  o.fit = true;
  LayoutReport rep;
  const Drawing out = lay_out(d, o, &rep);
  CHECK(rep.cropped.cut == 1);
  // what is left, 20 mm wide, is fitted to the whole sheet
  CHECK(points_of(out)[0].x == Approx(0));
  CHECK(points_of(out)[1].x == Approx(100));
}

TEST_CASE("area clipping keeps holes under both fill rules", "[layout][clip]") {
  Drawing d = page_with(100, 100);
  Area a;
  a.rings.push_back({{{10, 10}, {90, 10}, {90, 90}, {10, 90}, {10, 10}}});
  a.rings.push_back({{{40, 40}, {40, 60}, {60, 60}, {60, 40}, {40, 40}}});  // a hole, running the other way
  a.rule = FillRule::evenodd;
  d.layers[0].areas.push_back(a);
  LayoutOptions o;
  o.sheet = sheet(50, 100);  // cuts through the hole
  o.auto_rotate = false;
  const Drawing out = lay_out(d, o);
  const auto& rings = out.layers[0].areas.at(0).rings;
  REQUIRE(rings.size() == 2);
  for (const auto& r : rings) {
    CHECK(r.pts.front() == r.pts.back());
    for (const auto& p : r.pts) CHECK(p.x <= 50 + 1e-9);
  }
}

TEST_CASE("layers are chosen by number or name and mapped to pens by number, name or colour", "[layout][pens]") {
  Drawing d;
  const char* names[] = {"black", "red", "blue", "outline"};
  const Color cols[] = {colors::black, {255, 0, 0}, {0, 0, 255}, colors::black};
  for (int i = 0; i < 4; ++i) {
    Layer l;
    l.pen.name = names[i];
    l.pen.color = cols[i];
    l.lines.push_back({{{0, 0}, {1, 1}}});
    d.layers.push_back(l);
  }
  Drawing kept = d;
  keep_layers(kept, "2,outline");
  REQUIRE(kept.layers.size() == 2);
  CHECK(kept.layers[0].pen.name == "red");
  CHECK(kept.layers[0].pen.number == 2);  // the pen it had in the whole drawing
  CHECK(kept.layers[1].pen.number == 4);
  CHECK_THROWS_WITH(keep_layers(d, "7"), Catch::Contains("--layer 7") && Catch::Contains("2 red"));
  CHECK_THROWS_AS(keep_layers(d, "1,,2"), UserError);

  Drawing mapped = d;
  apply_pen_map(mapped, "#0000ff=1,red=1,outline=5");
  CHECK(mapped.layers[1].pen.number == 1);
  CHECK(mapped.layers[2].pen.number == 1);
  CHECK(mapped.layers[3].pen.number == 5);
  CHECK(mapped.layers[0].pen.number == 2);  // unnamed: the lowest number left free
  Drawing by_pos = d;
  apply_pen_map(by_pos, "4=1");
  CHECK(by_pos.layers[3].pen.number == 1);
  CHECK(by_pos.layers[0].pen.number == 2);
  CHECK_THROWS_WITH(apply_pen_map(d, "green=2"), Catch::Contains("green"));
  CHECK_THROWS_AS(apply_pen_map(d, "red=0"), UserError);
  CHECK_THROWS_AS(apply_pen_map(d, "red"), UserError);
}

TEST_CASE("pen numbers: numbered layers keep theirs, the rest take the lowest free", "[layout][pens]") {
  Drawing d;
  d.layers.resize(4);
  d.layers[1].pen.number = 1;
  d.layers[2].pen.number = 3;
  resolve_pen_numbers(d);
  CHECK(d.layers[0].pen.number == 2);
  CHECK(d.layers[1].pen.number == 1);
  CHECK(d.layers[2].pen.number == 3);
  CHECK(d.layers[3].pen.number == 4);
}
