#include "methods/tree/edges.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "util/error.hpp"

namespace stipplot::tree {

void EdgeParams::validate() const {
  require_range("--ms-spatial", spatial_radius, 1, 100);
  require_range("--ms-color", color_radius, 1, 255);
  require_range("--ms-scale", scale, 0.05, 1);
  require_range("--canny-low", canny_low, 0, 10000);
  require_range("--canny-high", canny_high, 0, 10000);
  if (canny_low > canny_high) throw UserError("--canny-low must not exceed --canny-high");
  if (min_length < 0 || min_length > 1'000'000) throw UserError("--min-edge-length must be in [0, 1000000]");
}

std::vector<uint8_t> major_edges(const Image& image, const EdgeParams& p) {
  p.validate();
  const int w = image.width, h = image.height;
  cv::Mat rgb(h, w, CV_8UC3, const_cast<uint8_t*>(image.rgb.data()));
  cv::Mat flat, grey, canny;
  // Mean shift on a reduced copy: the flattened regions, scaled back up, keep their
  // boundaries to a pixel or so, at a fraction of the cost.
  if (p.scale < 1) {
    cv::Mat small, small_flat;
    cv::resize(rgb, small, cv::Size(), p.scale, p.scale, cv::INTER_AREA);
    if (small.cols < 2 || small.rows < 2) small = rgb.clone();
    cv::pyrMeanShiftFiltering(small, small_flat, std::max(1.0, p.spatial_radius * small.cols / w), p.color_radius, 1);
    cv::resize(small_flat, flat, rgb.size(), 0, 0, cv::INTER_LINEAR);
  } else {
    cv::pyrMeanShiftFiltering(rgb, flat, p.spatial_radius, p.color_radius, 1);
  }
  cv::cvtColor(flat, grey, cv::COLOR_RGB2GRAY);
  cv::Canny(grey, canny, p.canny_low, p.canny_high, 3, true);
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(canny, labels, stats, centroids, 8, CV_32S);
  std::vector<uint8_t> keep(static_cast<size_t>(n), 0);
  for (int i = 1; i < n; ++i) keep[static_cast<size_t>(i)] = stats.at<int>(i, cv::CC_STAT_AREA) >= p.min_length;
  std::vector<uint8_t> out(image.pixels(), 0);
  for (int y = 0; y < h; ++y) {
    const int* row = labels.ptr<int>(y);
    for (int x = 0; x < w; ++x)
      if (keep[static_cast<size_t>(row[x])]) out[static_cast<size_t>(y) * w + x] = 255;
  }
  return out;
}

std::vector<float> distance_from(const std::vector<uint8_t>& mask, int width, int height) {
  cv::Mat src(height, width, CV_8U);
  bool any = false;
  for (int y = 0; y < height; ++y) {
    uint8_t* row = src.ptr<uint8_t>(y);
    for (int x = 0; x < width; ++x) {
      const bool set = mask[static_cast<size_t>(y) * width + x] != 0;
      row[x] = set ? 0 : 255;  // distanceTransform measures to the nearest zero
      any |= set;
    }
  }
  std::vector<float> out(static_cast<size_t>(width) * height);
  if (!any) {
    std::fill(out.begin(), out.end(), static_cast<float>(std::hypot(width, height)));
    return out;
  }
  cv::Mat dst(height, width, CV_32F, out.data());
  cv::distanceTransform(src, dst, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return out;
}

}  // namespace stipplot::tree
