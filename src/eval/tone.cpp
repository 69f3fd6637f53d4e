#include "eval/tone.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "detail/same_size.hpp"
#include "eval/bounded_blur.hpp"
#include "util/error.hpp"

namespace stipplot {

namespace eval_detail {

SameSize same_size(const Image& input, const Image& drawn, double sigma_px) {
  if (input.pixels() == 0 || drawn.pixels() == 0) throw UserError("fidelity: empty image");
  require_nonnegative("sigma", sigma_px);
  cv::Mat in(input.height, input.width, CV_8UC3, const_cast<uint8_t*>(input.rgb.data()));
  cv::Mat dr(drawn.height, drawn.width, CV_8UC3, const_cast<uint8_t*>(drawn.rgb.data()));
  // Compare at the smaller of the two resolutions (a 12-megapixel input against a
  // 150 dpi preview is compared at the preview's size), scaling the blur with it.
  SameSize s;
  s.sigma = sigma_px;
  if (drawn.width < input.width) {
    cv::resize(in, s.input, cv::Size(drawn.width, drawn.height), 0, 0, cv::INTER_AREA);
    s.sigma *= static_cast<double>(drawn.width) / input.width;
    s.drawn = dr;
  } else {
    s.input = in;
    cv::resize(dr, s.drawn, cv::Size(input.width, input.height), 0, 0, cv::INTER_AREA);
  }
  return s;
}

}  // namespace eval_detail

namespace {
cv::Mat blurred_grey(const cv::Mat& rgb8, double sigma) {
  cv::Mat f(rgb8.rows, rgb8.cols, CV_64F);
  for (int y = 0; y < rgb8.rows; ++y) {
    const uint8_t* p = rgb8.ptr<uint8_t>(y);
    double* o = f.ptr<double>(y);
    for (int x = 0; x < rgb8.cols; ++x) o[x] = (0.299 * p[3 * x] + 0.587 * p[3 * x + 1] + 0.114 * p[3 * x + 2]) / 255.0;
  }
  if (sigma > 0) gaussian_blur_bounded(f.clone(), f, sigma, cv::BORDER_REPLICATE);
  return f;
}
}  // namespace

ToneFit fit_tone(const Image& input, const Image& drawn, double sigma_px) {
  const eval_detail::SameSize s = eval_detail::same_size(input, drawn, sigma_px);
  const cv::Mat a = blurred_grey(s.input, s.sigma), b = blurred_grey(s.drawn, s.sigma);
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (int y = 0; y < a.rows; ++y) {
    const double* pa = a.ptr<double>(y);
    const double* pb = b.ptr<double>(y);
    for (int x = 0; x < a.cols; ++x) {
      sa += pa[x], sb += pb[x];
      saa += pa[x] * pa[x], sbb += pb[x] * pb[x], sab += pa[x] * pb[x];
    }
  }
  const double n = static_cast<double>(a.total());
  ToneFit f;
  f.mean_input = sa / n;
  f.mean_drawn = sb / n;
  const double va = saa / n - f.mean_input * f.mean_input, vb = sbb / n - f.mean_drawn * f.mean_drawn;
  const double cov = sab / n - f.mean_input * f.mean_drawn;
  // A flat input has no tone to follow: slope and r are undefined, reported as 0.
  if (va > 1e-12) f.slope = cov / va;
  f.intercept = f.mean_drawn - f.slope * f.mean_input;
  if (va > 1e-12 && vb > 1e-12) f.pearson = cov / std::sqrt(va * vb);
  return f;
}

}  // namespace stipplot
