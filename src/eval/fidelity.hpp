#pragma once
// How faithfully a drawing reproduces its input (`stipplot eval`).
//  - Blurred SSIM: both images Gaussian-blurred at the dot spacing, then SSIM
//    (Wang et al. 2004, 11x11 Gaussian window, sigma 1.5) on grey levels.
//  - Edge spill: of the dots within 1.5 px of a strong edge of the input, the share
//    on the wrong side of it: dark ink on the bright side, light ink on the dark side.
#include <string>

#include "geometry/page.hpp"
#include "image/image.hpp"

namespace stipplot {

struct FidelityOptions {
  double sigma = 0;           // blur in input pixels; 0 = the measured dot spacing
  double edge_distance = 1.5; // px
  double ink_threshold = 40;  // grey levels away from the paper to count as ink
};

struct FidelityResult {
  double ssim_blurred = 0;
  double sigma = 0;          // the blur used
  double dot_spacing = 0;    // sqrt(area / dots)
  double mark_spacing = 0;   // of the ink blobs' centres (eval/mark_spacing.hpp), input px
  size_t dots = 0, dark_dots = 0, light_dots = 0;
  size_t dots_near_edges = 0, spilled = 0;
  double edge_spill = 0;     // spilled / dots_near_edges (0 when none near edges)
  int paper_level = 0;
};

// `drawn` is the drawing as seen over exactly the input's extent, at any resolution.
// O(pixels of both images).
FidelityResult evaluate_fidelity(const Image& input, const Image& drawn, const FidelityOptions& opt = {});

// Cuts the image's rectangle out of a whole-page preview, given how the image was
// placed on the page. Throws UserError when the preview's shape does not match the page.
Image crop_to_image(const Image& page_preview, const PageTransform& placement, int input_w, int input_h);

// SSIM of two equally sized grey images (8-bit), exposed for tests.
double ssim(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, int w, int h);

}  // namespace stipplot
