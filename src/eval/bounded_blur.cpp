#include "eval/bounded_blur.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace stipplot {

void gaussian_blur_bounded(const cv::Mat& in, cv::Mat& out, double sigma, int border) {
  if (sigma <= kDirectSigma) {
    cv::GaussianBlur(in, out, cv::Size(0, 0), sigma, sigma, border);
    return;
  }
  const double shrink = sigma / kDirectSigma;
  const cv::Size small(std::max(1, static_cast<int>(std::lround(in.cols / shrink))),
                       std::max(1, static_cast<int>(std::lround(in.rows / shrink))));
  cv::Mat s, b;
  cv::resize(in, s, small, 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(s, b, cv::Size(0, 0), kDirectSigma, kDirectSigma, border);
  cv::resize(b, out, in.size(), 0, 0, cv::INTER_LINEAR);
}

}  // namespace stipplot
