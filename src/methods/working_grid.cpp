#include "methods/working_grid.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "util/error.hpp"

namespace stipplot {

WorkingGrid make_working_grid(const Image& image, const PageTransform& tf, double cell_mm, size_t max_cells) {
  if (image.pixels() == 0) throw UserError("image has no pixels");
  require_positive("working grid cell", cell_mm);
  const double w_mm = image.width * tf.mm_per_px(), h_mm = image.height * tf.mm_per_px();
  // Enlarge the cell until the grid fits the cell budget.
  cell_mm = std::max(cell_mm, std::sqrt(w_mm * h_mm / static_cast<double>(max_cells)));
  const int gw = std::max(1, static_cast<int>(std::lround(w_mm / cell_mm)));
  const int gh = std::max(1, static_cast<int>(std::lround(h_mm / cell_mm)));
  WorkingGrid g;
  g.cell_mm = w_mm / gw;
  g.origin_mm = tf.map(0, 0);
  g.image.width = gw;
  g.image.height = gh;
  g.image.rgb.resize(g.image.pixels() * 3);
  const cv::Mat src(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.rgb.data()));
  cv::Mat dst(gh, gw, CV_8UC3, g.image.rgb.data());
  if (gw == image.width && gh == image.height) {
    src.copyTo(dst);
  } else {
    const bool shrink = gw <= image.width && gh <= image.height;
    cv::resize(src, dst, cv::Size(gw, gh), 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  }
  return g;
}

}  // namespace stipplot
