// The pen-true render: strokes at the pen's width and colour, a pen's own ink one layer,
// dark ink multiplying, light ink covering.
#include <catch2/catch.hpp>

#include "preview/preview.hpp"
#include "test_util.hpp"
#include "util/error.hpp"

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

TEST_CASE("the first pen, drawn straight on the paper, looks as it does drawn after another pen", "[preview]") {
  // The first layer skips the page-sized group (its composite over bare paper is the ink
  // times the paper); a later layer is composited as a group. Both give the same pixels.
  PlannedLayer ink, far;
  ink.pen = Pen{"blue", Color{40, 60, 200}, 0.7};
  ink.strokes.push_back({{{3, 3}, {15, 7.3}}});
  ink.strokes.push_back({{{6, 6.2}}});
  far.pen = Pen{"red", Color{200, 30, 30}, 0.5};
  far.strokes.push_back({{{19.5, 0.5}}});  // away from the blue ink
  for (const Color paper : {colors::white, Color{230, 220, 180}}) {
    Plan alone = page_plan(paper), second = page_plan(paper);
    alone.layers = {ink};
    second.layers = {far, ink};
    const Image a = render_plan(alone, opts()), b = render_plan(second, opts());
    REQUIRE(a.rgb.size() == b.rgb.size());
    int worst = 0;
    for (size_t i = 0; i < a.rgb.size(); ++i)
      if (i / 3 % a.width < 190) worst = std::max(worst, std::abs(int{a.rgb[i]} - int{b.rgb[i]}));
    CHECK(worst <= 1);  // rounding of the composite
    CHECK(at(a, 9, 5.15) != paper);  // the stroke is there
  }
}

TEST_CASE("images written as PNG and TGA read back pixel for pixel", "[preview][image]") {
  test::TempDir t;
  Image im;
  im.width = 37;
  im.height = 11;
  im.rgb.resize(im.pixels() * 3);
  for (size_t i = 0; i < im.rgb.size(); ++i) im.rgb[i] = static_cast<uint8_t>(i * 7 % 251);
  write_png(im, t.file("a.png"));
  write_tga(im, t.file("a.tga"));
  for (const char* f : {"a.png", "a.tga"}) {
    const Image back = load_image(t.file(f));
    CHECK(back.width == im.width);
    CHECK(back.height == im.height);
    CHECK(back.rgb == im.rgb);
  }
  CHECK_THROWS_AS(write_png(Image{}, t.file("empty.png")), UserError);
  CHECK_FALSE(std::filesystem::exists(t.file("empty.png")));
}
