#pragma once
// Stippling by grayscale-order Poisson disk sampling (seed 000, SPEC.md §1):
// random order, grayscale order, negative, binary, RGB colour (the paper's 27
// colours) and a CMYK ink separation for plotting.
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "geometry/drawing.hpp"
#include "image/image.hpp"
#include "methods/placement.hpp"

namespace stipplot {

enum class StippleMethod { Random, Gray, Negative, Binary, Color, Cmyk };

// "random", "gray", ... ; throws UserError for anything else.
StippleMethod parse_stipple_method(const std::string& name);
const char* to_string(StippleMethod m);

struct StippleParams {
  StippleMethod method = StippleMethod::Gray;
  double a = 3, b = 15;                    // r = a + b d/255 (paper: faces 3, 15; thin lines 1, 4)
  double a_b = 3, b_b = 15, a_w = 3, b_w = 15;  // binary: black s = a_b + b_b d/255, white t = a_w + b_w (255-d)/255
  uint64_t seed = 1;
  void validate() const;  // UserError naming the parameter
};

// Dots in pixel space, one list per output layer, before placement on the page.
struct StippleLayer {
  Pen pen;                      // colour and name of the ink
  std::vector<uint32_t> dots;   // pixel indices y * width + x
};
struct StippleResult {
  int width = 0, height = 0;
  Color paper = colors::white;
  std::vector<StippleLayer> layers;
};

// The method proper, in pixel space. Time O(n) for ordering plus the sampling's
// O(n * (r_max/g + 2)^2 * c) grid queries (n pixels, g grid cell, c cell capacity);
// colour/CMYK run three or four channels.
// `progress` (optional) receives the fraction done; it never changes the result.
StippleResult stipple_pixels(const Image& image, const StippleParams& params,
                             const std::function<void(double)>& progress = {});

// Pure function from image + parameters to a Drawing: stipple_pixels placed on the page.
Drawing stipple(const Image& image, const StippleParams& params, const Placement& placement,
                const std::function<void(double)>& progress = {});

// Lays pixel-space dots on the page as pen dots.
Drawing place_stipple(const StippleResult& r, const Placement& placement);

}  // namespace stipplot
