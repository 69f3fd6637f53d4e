#include "eval/color_difference.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "eval/bounded_blur.hpp"
#include "util/error.hpp"

namespace stipplot {

namespace {
cv::Mat lab_blurred(const cv::Mat& rgb8, double sigma) {
  cv::Mat f;
  rgb8.convertTo(f, CV_32FC3, 1.0 / 255);
  if (sigma > 0) gaussian_blur_bounded(f.clone(), f, sigma, cv::BORDER_REPLICATE);
  cv::Mat lab;
  cv::cvtColor(f, lab, cv::COLOR_RGB2Lab);
  return lab;
}
}  // namespace

double mean_delta_e00_blurred(const Image& input, const Image& drawn, double sigma_px) {
  if (input.pixels() == 0 || drawn.pixels() == 0) throw UserError("colour fidelity: empty image");
  require_nonnegative("sigma", sigma_px);
  cv::Mat in(input.height, input.width, CV_8UC3, const_cast<uint8_t*>(input.rgb.data()));
  cv::Mat dr(drawn.height, drawn.width, CV_8UC3, const_cast<uint8_t*>(drawn.rgb.data()));
  // Compare at the smaller of the two resolutions (a 12-megapixel input against a
  // 150 dpi preview is compared at the preview's size), scaling the blur with it.
  cv::Mat a = in, b;
  double sigma = sigma_px;
  if (drawn.width < input.width) {
    cv::resize(in, a, cv::Size(drawn.width, drawn.height), 0, 0, cv::INTER_AREA);
    sigma *= static_cast<double>(drawn.width) / input.width;
    b = dr;
  } else {
    cv::resize(dr, b, cv::Size(input.width, input.height), 0, 0, cv::INTER_AREA);
  }
  const cv::Mat la = lab_blurred(a, sigma), lb = lab_blurred(b, sigma);
  double total = 0;
  for (int y = 0; y < la.rows; ++y) {
    const cv::Vec3f* pa = la.ptr<cv::Vec3f>(y);
    const cv::Vec3f* pb = lb.ptr<cv::Vec3f>(y);
    for (int x = 0; x < la.cols; ++x)
      total += ciede2000({pa[x][0], pa[x][1], pa[x][2]}, {pb[x][0], pb[x][1], pb[x][2]});
  }
  return total / static_cast<double>(la.total());
}

}  // namespace stipplot
