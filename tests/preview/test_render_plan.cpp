// The pen-true render: strokes at the pen's width and colour, a pen's own ink one layer,
// dark ink multiplying, light ink covering.
#include <catch2/catch.hpp>

#include "preview/preview.hpp"

using namespace stipplot;

namespace {
// 20 x 10 mm page at 254 dpi: 10 px a mm.
Plan page_plan(Color paper = colors::white) {
  Plan p;
  p.page = {20, 10, paper};
  return p;
}
PreviewOptions opts() {
  PreviewOptions o;
  o.dpi = 254;
  return o;
}
Color at(const Image& im, double x_mm, double y_mm) {
  const int x = static_cast<int>(x_mm * 10), y = static_cast<int>(y_mm * 10);
  const size_t o = (static_cast<size_t>(y) * im.width + x) * 3;
  return {im.rgb[o], im.rgb[o + 1], im.rgb[o + 2]};
}
}  // namespace

TEST_CASE("the pen-true render draws touches and strokes at the pen's width", "[preview]") {
  Plan p = page_plan();
  PlannedLayer l;
  l.pen = Pen{"black", colors::black, 1.0};
  l.strokes.push_back({{{5, 5}}});                // a touch: a 1 mm disc
  l.strokes.push_back({{{10, 2}, {18, 2}}});      // a line 1 mm wide
  p.layers.push_back(l);
  const Image im = render_plan(p, opts());
  CHECK(im.width == 200);
  CHECK(at(im, 5, 5) == colors::black);
  CHECK(at(im, 5.35, 5) == colors::black);  // inside the 0.5 mm radius
  CHECK(at(im, 5.7, 5) == colors::white);   // outside it
  CHECK(at(im, 14, 2.35) == colors::black);
  CHECK(at(im, 14, 2.7) == colors::white);
}

TEST_CASE("a pen over its own ink does not darken it, another pen's ink multiplies", "[preview]") {
  Plan p = page_plan();
  PlannedLayer cyan, magenta;
  cyan.pen = Pen{"cyan", Color{0, 255, 255}, 2.0};
  cyan.strokes.push_back({{{4, 5}, {12, 5}}});
  cyan.strokes.push_back({{{8, 2}, {8, 8}}});  // crosses the first stroke at (8, 5)
  magenta.pen = Pen{"magenta", Color{255, 0, 255}, 2.0};
  magenta.strokes.push_back({{{11, 5}, {16, 5}}});
  p.layers = {cyan, magenta};
  const Image im = render_plan(p, opts());
  CHECK(at(im, 8, 5) == Color{0, 255, 255});   // cyan twice is still cyan
  CHECK(at(im, 11.5, 5) == Color{0, 0, 255});  // cyan x magenta = blue
  CHECK(at(im, 15, 5) == Color{255, 0, 255});
}

TEST_CASE("ink lighter than the paper covers it, as a gel pen does", "[preview]") {
  Plan p = page_plan(colors::grey);
  PlannedLayer white, black;
  white.pen = Pen{"white", colors::white, 2.0};
  white.strokes.push_back({{{5, 5}}});
  black.pen = Pen{"black", colors::black, 2.0};
  black.strokes.push_back({{{12, 5}}});
  p.layers = {white, black};
  const Image im = render_plan(p, opts());
  CHECK(at(im, 5, 5) == colors::white);
  CHECK(at(im, 12, 5) == colors::black);
  CHECK(at(im, 18, 8) == colors::grey);
}
