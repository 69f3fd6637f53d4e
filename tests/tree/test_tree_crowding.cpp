// Trees a pen can draw: where many MST lines meet, their ink would fill the point's
// surroundings (a blot); the lines stop short of crowded points so the ink in a 1 mm disc
// around the busiest points of SIBD and BD trees stays below a solid fill, while the tree
// keeps almost all its drawn length (its shape). CSIBD gets the same gaps, but its edge
// pixels, a pixel apart, draw the major edges as solid lines on purpose, so a disc on them
// is dark whatever the gaps: it is not measured here.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "methods/tree/tree.hpp"
#include "preview/preview.hpp"
#include "test_util.hpp"

using namespace stipplot;

TEST_CASE("the gap at a crowded point keeps its disc's coverage and is none where few lines meet", "[tree]") {
  // A branch point (three lines) is no crowd.
  CHECK(tree::crowd_gap_mm(2, 0.3) == 0);
  CHECK(tree::crowd_gap_mm(3, 0.3) == 0);
  double last = 0;
  for (size_t n : {5, 8, 20, 70}) {
    const double g = tree::crowd_gap_mm(n, 0.3);
    INFO(n << " lines: gap " << g);
    CHECK(g > last);  // more lines, a wider gap
    CHECK(g < 0.5);
    last = g;
    CHECK(static_cast<double>(n) * 0.3 * (0.5 - g) == Approx(tree::kCrowdCoverage * M_PI * 0.25));
  }
}

namespace {
// Mean ink (1 - luma) of the rendered page in a disc of `d_mm` around `c_mm`.
double disc_ink(const Image& img, double dpi, Vec2 c_mm, double d_mm) {
  const double s = dpi / 25.4, r = d_mm / 2 * s, cx = c_mm.x * s, cy = c_mm.y * s;
  double ink = 0, n = 0;
  for (int y = std::max(0, int(cy - r)); y <= std::min(img.height - 1, int(cy + r) + 1); ++y)
    for (int x = std::max(0, int(cx - r)); x <= std::min(img.width - 1, int(cx + r) + 1); ++x) {
      if ((x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - cy) * (y + 0.5 - cy) > r * r) continue;
      const uint8_t* p = &img.rgb[(static_cast<size_t>(y) * img.width + x) * 3];
      ink += 1 - (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
      n += 1;
    }
  return n > 0 ? ink / n : 0;
}
}  // namespace

TEST_CASE("the busiest points of SIBD and BD trees plot below a solid fill", "[tree][slow]") {
  const Image img = load_image(std::string(STIPPLOT_SOURCE_DIR) + "/examples/coffee.png");
  for (const char* variant : {"sibd", "bd"}) {
    tree::TreeParams p;
    p.variant = tree::parse_variant(variant);
    const tree::TreeResult r = tree::tree_pixels(img, p);
    Placement pl;
    pl.page = PageSpec{90, 60};
    pl.margin_mm = 0;
    const PageTransform tf = pl.transform(img.width, img.height);
    const Drawing d = tree::place_tree(r, pl);
    std::vector<uint32_t> degree(r.points.size());
    double full_len = 0, drawn_len = 0;
    for (const auto& e : r.layers[0].edges) {
      ++degree[e.a], ++degree[e.b];
      full_len += std::hypot(r.points.x[e.a] - r.points.x[e.b], r.points.y[e.a] - r.points.y[e.b]) * tf.mm_per_px();
    }
    for (const auto& l : d.layers[0].lines)
      drawn_len += std::hypot(l.pts[1].x - l.pts[0].x, l.pts[1].y - l.pts[0].y);
    std::vector<uint32_t> order(r.stipple_count);
    std::iota(order.begin(), order.end(), 0u);
    std::partial_sort(order.begin(), order.begin() + 10, order.end(),
                      [&](uint32_t a, uint32_t b) { return degree[a] > degree[b]; });
    PreviewOptions po;
    po.dpi = 1200;
    const Image page = render_preview(d, po);
    double worst = 0;
    for (int i = 0; i < 10; ++i) {
      const uint32_t k = order[static_cast<size_t>(i)];
      worst = std::max(worst, disc_ink(page, po.dpi, tf.map(r.points.x[k] + 0.5, r.points.y[k] + 0.5), 1.0));
    }
    INFO(variant << ": busiest point joins " << degree[order[0]] << " lines; worst 1 mm disc ink " << worst
                 << "; drawn length " << drawn_len / full_len << " of the tree's");
    CHECK(degree[order[0]] >= 5);  // crowded points exist: the test means something
    CHECK(worst <= 0.8);
    CHECK(drawn_len >= 0.9 * full_len);
  }
}
