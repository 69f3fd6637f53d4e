// Sketch strokes linked into scribbles (methods/sketch/link.hpp): every stroke drawn
// whole, far fewer pen lifts, and no link over ground its pen is not for.
#include <catch2/catch.hpp>
#include <cmath>

#include "image/image.hpp"
#include "methods/sketch/link.hpp"
#include "methods/sketch/sketch.hpp"
#include "util/error.hpp"

using namespace stipplot;
using namespace stipplot::sketch;

namespace {
// Grey (level `g`) on the left and right thirds, white in the middle.
Image two_fields(int w, int h, uint8_t g) {
  Image im;
  im.width = w, im.height = h;
  im.rgb.assign(im.pixels() * 3, 255);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (x < w / 3 || x >= 2 * w / 3)
        for (int c = 0; c < 3; ++c) im.rgb[(static_cast<size_t>(y) * w + x) * 3 + c] = g;
  return im;
}

size_t points_of(const Layer& l) {
  size_t n = 0;
  for (const auto& pl : l.lines) n += pl.pts.size();
  return n;
}

// Is `s` (or its reverse) a contiguous run of `line`'s points?
bool contains_run(const Polyline& line, const Polyline& s) {
  const auto& a = line.pts;
  for (int dir = 0; dir < 2; ++dir) {
    std::vector<Vec2> pat = s.pts;
    if (dir) std::reverse(pat.begin(), pat.end());
    if (std::search(a.begin(), a.end(), pat.begin(), pat.end()) != a.end()) return true;
  }
  return false;
}
}  // namespace

TEST_CASE("linked sketch strokes: each drawn whole, far fewer lines, no link across white ground", "[sketch][link]") {
  SketchParams p;
  p.space = ColorSpace::Pens;
  p.pens = {Pen{"black", colors::black, 0.3}};
  Placement place;
  place.page = PageSpec{150, 60};
  place.margin_mm = 5;
  const SketchResult r = sketch_strokes(two_fields(300, 100, 100), p, place);
  const Drawing kept = to_drawing(r);
  REQUIRE(kept.layers.size() == 1);
  LinkStats st;
  const Drawing linked = link_strokes(r, kept, 1.0, LinkParams{}, &st);
  REQUIRE(linked.layers.size() == 1);
  const Layer& in = kept.layers[0];
  const Layer& out = linked.layers[0];
  INFO(in.lines.size() << " strokes -> " << out.lines.size() << " lines, " << st.links << " links, " << st.link_mm << " mm");
  CHECK(st.strokes == in.lines.size());
  CHECK(st.lines == out.lines.size());
  CHECK(out.lines.size() * 10 < in.lines.size());
  CHECK(points_of(out) == points_of(in));  // links add no points: they join ends
  // Every stroke is a run of one line, forwards or back (sampled: the search is O(n^2)).
  for (size_t i = 0; i < in.lines.size(); i += 37) {
    bool found = false;
    for (const auto& l : out.lines) found = found || contains_run(l, in.lines[i]);
    CHECK(found);
  }
  // The white band (the middle third of the image's width on the page) is never crossed.
  const double x0 = r.grid_origin_mm.x + r.grid_w * r.cell_w_mm / 3, x1 = r.grid_origin_mm.x + 2 * r.grid_w * r.cell_w_mm / 3;
  size_t crossings = 0;
  for (const auto& l : out.lines)
    for (size_t k = 1; k < l.pts.size(); ++k)
      if ((l.pts[k - 1].x < x0 && l.pts[k].x > x1) || (l.pts[k].x < x0 && l.pts[k - 1].x > x1)) ++crossings;
  CHECK(crossings == 0);
  // Without links (a zero link length), the strokes come back one a line.
  LinkParams none;
  none.lift_length = 0;
  CHECK(link_strokes(r, kept, 1.0, none).layers[0].lines.size() == in.lines.size());
}

TEST_CASE("linked sketch: bad link parameters are refused naming the option", "[sketch][link]") {
  SketchResult r;
  Drawing d;
  LinkParams p;
  p.lift_length = -1;
  CHECK_THROWS_WITH(link_strokes(r, d, 1.0, p), Catch::Contains("--link-length"));
  p = LinkParams{};
  p.lift_tone = std::nan("");
  CHECK_THROWS_WITH(link_strokes(r, d, 1.0, p), Catch::Contains("--link-tone"));
  CHECK_THROWS_AS(link_strokes(r, d, 0.0, LinkParams{}), UserError);
}
