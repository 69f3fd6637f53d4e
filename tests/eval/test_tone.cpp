// The tone fit: blurred drawing grey against blurred input grey.
#include <catch2/catch.hpp>

#include "eval/tone.hpp"

using namespace stipplot;

namespace {
// A horizontal ramp from black to white, `w` x `h`.
Image ramp(int w, int h, double fade = 1.0) {
  std::vector<uint8_t> g(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double v = 255.0 * x / (w - 1);
      g[static_cast<size_t>(y) * w + x] = static_cast<uint8_t>(std::lround(255 - fade * (255 - v)));
    }
  return Image::from_grey(w, h, g);
}
}  // namespace

TEST_CASE("the tone fit of an image with itself has slope 1 and r 1", "[eval][tone]") {
  const Image a = ramp(200, 50);
  const ToneFit f = fit_tone(a, a, 3);
  CHECK(f.slope == Approx(1).margin(1e-9));
  CHECK(f.intercept == Approx(0).margin(1e-9));
  CHECK(f.pearson == Approx(1).margin(1e-9));
}

TEST_CASE("a faded drawing has the fading as its slope, at any resolution", "[eval][tone]") {
  const Image in = ramp(200, 50), half = ramp(400, 100, 0.5);
  const ToneFit f = fit_tone(in, half, 3);
  CHECK(f.slope == Approx(0.5).margin(0.01));
  CHECK(f.pearson > 0.999);
  CHECK(f.mean_drawn > f.mean_input);
}
