#pragma once
// Private to stipplot_eval: an input and a drawing of its extent brought to one size.
#include <opencv2/core.hpp>

#include "image/image.hpp"

namespace stipplot::eval_detail {

// Both as 8-bit RGB mats at the smaller of the two resolutions (area resampling), and the
// blur `sigma_px` (input pixels) scaled to that size. The mats may share the images' data.
struct SameSize {
  cv::Mat input, drawn;
  double sigma = 0;
};
SameSize same_size(const Image& input, const Image& drawn, double sigma_px);

}  // namespace stipplot::eval_detail
