#include "eval/color_difference.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "detail/same_size.hpp"
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
  const eval_detail::SameSize s = eval_detail::same_size(input, drawn, sigma_px);
  const cv::Mat la = lab_blurred(s.input, s.sigma), lb = lab_blurred(s.drawn, s.sigma);
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
