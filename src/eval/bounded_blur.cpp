#include "eval/bounded_blur.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "util/threads.hpp"

namespace stipplot {

void gaussian_blur_rows(const cv::Mat& in, cv::Mat& out, double sigma, int border) {
  constexpr int kBand = 128;
  const int bands = (in.rows + kBand - 1) / kBand;
  if (bands < 2 || thread_count() < 2 || in_parallel_part()) {
    cv::GaussianBlur(in, out, cv::Size(0, 0), sigma, sigma, border);
    return;
  }
  // Every band reads rows of `in` beyond its own: in place, they would read blurred ones.
  const bool in_place = in.data == out.data;
  cv::Mat to_fill = in_place ? cv::Mat(in.size(), in.type()) : (out.create(in.size(), in.type()), out);
#pragma omp parallel for schedule(dynamic, 1) num_threads(thread_count())
  for (int b = 0; b < bands; ++b) {
    const cv::Rect band(0, b * kBand, in.cols, std::min(kBand, in.rows - b * kBand));
    cv::Mat to = to_fill(band);
    cv::GaussianBlur(in(band), to, cv::Size(0, 0), sigma, sigma, border);
  }
  if (in_place) to_fill.copyTo(out);
}

void gaussian_blur_bounded(const cv::Mat& in, cv::Mat& out, double sigma, int border) {
  if (sigma <= kDirectSigma) {
    gaussian_blur_rows(in, out, sigma, border);
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
