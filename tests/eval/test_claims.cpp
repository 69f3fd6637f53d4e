// The paper's two claims, measured with the eval metrics on images like its figures.
#include <catch2/catch.hpp>

#include "eval/fidelity.hpp"
#include "methods/stipple/stipple.hpp"
#include "preview/preview.hpp"
#include "test_util.hpp"
#include "util/rng.hpp"

using namespace stipplot;

namespace {

// Stipple, render what the pens draw over exactly the image (1 mm a pixel, 4 px a mm),
// and measure it against the input.
FidelityResult measure(const Image& img, StippleMethod m, double a, double b, uint64_t seed) {
  StippleParams p;
  p.method = m;
  p.a = p.a_b = p.a_w = a;
  p.b = p.b_b = p.b_w = b;
  p.seed = seed;
  Placement pl;
  pl.page = {static_cast<double>(img.width), static_cast<double>(img.height)};
  pl.margin_mm = 0;
  pl.pen_width_mm = 1.0;  // one-pixel dots, as in the paper
  Drawing d = stipple(img, p, pl);
  PreviewOptions po;
  po.dpi = 25.4 * 4;
  Image drawn = render_preview(d, po);
  return evaluate_fidelity(img, drawn);
}

struct Mean {
  double ssim = 0, spill = 0;
};
Mean mean_over_seeds(const Image& img, StippleMethod m, double a, double b) {
  Mean r;
  const int seeds = 3;
  for (int s = 1; s <= seeds; ++s) {
    auto f = measure(img, m, a, b, static_cast<uint64_t>(s));
    r.ssim += f.ssim_blurred / seeds;
    r.spill += f.edge_spill / seeds;
  }
  return r;
}

}  // namespace

TEST_CASE("claim 1: grayscale order keeps edges and thin lines clearer than random order", "[claims][eval]") {
  Image img = test::spiral_image(256);
  // Edge spill, at the paper's thin-line (a=1, b=4) and face (a=3, b=15) settings and
  // the tree method's (2, 8): grayscale order puts (almost) no dot on the bright side.
  for (auto [a, b] : std::vector<std::pair<double, double>>{{1, 4}, {2, 8}, {3, 15}}) {
    Mean gray = mean_over_seeds(img, StippleMethod::Gray, a, b);
    Mean rnd = mean_over_seeds(img, StippleMethod::Random, a, b);
    INFO("a=" << a << " b=" << b << " gray: ssim " << gray.ssim << " spill " << gray.spill << "; random: ssim "
              << rnd.ssim << " spill " << rnd.spill);
    CHECK(gray.spill < 0.5 * rnd.spill);
    // Blurred SSIM: at (1, 4) the two tie (README), because the blur at the dot spacing
    // is wider than the halo grayscale order leaves beside a line; at the coarser
    // settings grayscale order wins.
    if (a > 1) CHECK(gray.ssim > rnd.ssim);
  }
}

TEST_CASE("claim 2: on grey with white and black lines, binary beats both one-colour stipples",
          "[claims][eval]") {
  Image img = test::grey_lines_image(256, 256);
  Mean bin = mean_over_seeds(img, StippleMethod::Binary, 1, 4);
  Mean gray = mean_over_seeds(img, StippleMethod::Gray, 1, 4);
  Mean neg = mean_over_seeds(img, StippleMethod::Negative, 1, 4);
  INFO("binary " << bin.ssim << ", black on white " << gray.ssim << ", white on black " << neg.ssim);
  CHECK(bin.ssim > gray.ssim);
  CHECK(bin.ssim > neg.ssim);
}

TEST_CASE("SSIM is 1 for identical images and drops with noise", "[eval]") {
  std::vector<uint8_t> a(64 * 64), b(64 * 64);
  Rng rng(1);
  for (size_t i = 0; i < a.size(); ++i) {
    a[i] = static_cast<uint8_t>((i % 64) * 4);
    b[i] = static_cast<uint8_t>(std::clamp<int>(a[i] + static_cast<int>(rng.below(81)) - 40, 0, 255));
  }
  CHECK(ssim(a, a, 64, 64) == Approx(1.0));
  CHECK(ssim(a, b, 64, 64) < 0.9);
}

TEST_CASE("eval crops the image area out of a page preview", "[eval]") {
  Image page;
  page.width = 210;
  page.height = 297;
  page.rgb.assign(page.pixels() * 3, 255);
  PageTransform tf(100, 50, parse_page("A4"), 10, false);  // 1.9 mm a pixel
  Image crop = crop_to_image(page, tf, 100, 50);
  CHECK(crop.width == 190);
  CHECK(crop.height == 95);
  Image wrong = page;
  wrong.width = 297;
  wrong.height = 210;
  CHECK_THROWS_WITH(crop_to_image(wrong, tf, 100, 50), Catch::Contains("--page"));
}
