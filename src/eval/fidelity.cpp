#include "eval/fidelity.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "eval/mark_spacing.hpp"
#include "eval/bounded_blur.hpp"
#include "util/error.hpp"

namespace stipplot {

namespace {

cv::Mat grey_mat(const Image& im) {
  cv::Mat m(im.height, im.width, CV_8UC1);
  auto l = im.luma();
  std::copy(l.begin(), l.end(), m.data);
  return m;
}

double ssim_mat(const cv::Mat& a8, const cv::Mat& b8) {
  cv::Mat a, b;
  a8.convertTo(a, CV_64F);
  b8.convertTo(b, CV_64F);
  const double C1 = std::pow(0.01 * 255, 2), C2 = std::pow(0.03 * 255, 2);
  const cv::Size win(11, 11);
  const double s = 1.5;
  cv::Mat mu_a, mu_b, aa, bb, ab;
  cv::GaussianBlur(a, mu_a, win, s);
  cv::GaussianBlur(b, mu_b, win, s);
  cv::GaussianBlur(a.mul(a), aa, win, s);
  cv::GaussianBlur(b.mul(b), bb, win, s);
  cv::GaussianBlur(a.mul(b), ab, win, s);
  cv::Mat mu_a2 = mu_a.mul(mu_a), mu_b2 = mu_b.mul(mu_b), mu_ab = mu_a.mul(mu_b);
  cv::Mat var_a = aa - mu_a2, var_b = bb - mu_b2, cov = ab - mu_ab;
  cv::Mat num = (2 * mu_ab + C1).mul(2 * cov + C2);
  cv::Mat den = (mu_a2 + mu_b2 + C1).mul(var_a + var_b + C2);
  cv::Mat map;
  cv::divide(num, den, map);
  return cv::mean(map)[0];
}

}  // namespace

double ssim(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, int w, int h) {
  cv::Mat ma(h, w, CV_8UC1, const_cast<uint8_t*>(a.data()));
  cv::Mat mb(h, w, CV_8UC1, const_cast<uint8_t*>(b.data()));
  return ssim_mat(ma, mb);
}

Image crop_to_image(const Image& page, const PageTransform& tf, int iw, int ih) {
  const double sx = page.width / tf.page_w(), sy = page.height / tf.page_h();
  if (std::abs(sx - sy) > 0.02 * std::max(sx, sy))
    throw UserError("the preview's shape does not match the page; pass eval the --page, --margin and --landscape "
                    "used to make it");
  int x0 = static_cast<int>(std::lround(tf.origin_x() * sx)), y0 = static_cast<int>(std::lround(tf.origin_y() * sy));
  int cw = static_cast<int>(std::lround(iw * tf.mm_per_px() * sx)), ch = static_cast<int>(std::lround(ih * tf.mm_per_px() * sy));
  x0 = std::clamp(x0, 0, page.width - 1);
  y0 = std::clamp(y0, 0, page.height - 1);
  cw = std::clamp(cw, 1, page.width - x0);
  ch = std::clamp(ch, 1, page.height - y0);
  Image out;
  out.width = cw;
  out.height = ch;
  out.rgb.resize(out.pixels() * 3);
  for (int y = 0; y < ch; ++y)
    std::copy_n(&page.rgb[((static_cast<size_t>(y0 + y)) * page.width + x0) * 3], static_cast<size_t>(cw) * 3,
                &out.rgb[static_cast<size_t>(y) * cw * 3]);
  return out;
}

FidelityResult evaluate_fidelity(const Image& input, const Image& drawn, const FidelityOptions& opt) {
  require_nonnegative("--sigma", opt.sigma);
  require_nonnegative("--edge-distance", opt.edge_distance);
  if (input.pixels() == 0 || drawn.pixels() == 0) throw UserError("eval: empty image");
  FidelityResult res;
  cv::Mat in = grey_mat(input);
  cv::Mat dr_full = grey_mat(drawn);

  // The paper is the most common level of the drawing.
  int hist[256] = {0};
  for (int y = 0; y < dr_full.rows; ++y)
    for (int x = 0; x < dr_full.cols; ++x) ++hist[dr_full.at<uint8_t>(y, x)];
  res.paper_level = static_cast<int>(std::max_element(hist, hist + 256) - hist);

  // Dots: connected blobs of ink at the drawing's own resolution, centroids mapped
  // to input pixels.
  const double fx = static_cast<double>(input.width) / drawn.width, fy = static_cast<double>(input.height) / drawn.height;
  struct Blob {
    double x, y;
    bool dark;
  };
  std::vector<Blob> blobs;
  for (int pass = 0; pass < 2; ++pass) {
    cv::Mat mask;
    if (pass == 0)
      mask = dr_full < (res.paper_level - opt.ink_threshold);
    else
      mask = dr_full > (res.paper_level + opt.ink_threshold);
    cv::Mat labels, stats, centroids;
    int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
    for (int i = 1; i < n; ++i)
      blobs.push_back({centroids.at<double>(i, 0) * fx, centroids.at<double>(i, 1) * fy, pass == 0});
  }
  res.dots = blobs.size();
  for (const auto& b : blobs) (b.dark ? res.dark_dots : res.light_dots)++;
  res.dot_spacing = res.dots ? std::sqrt(static_cast<double>(input.pixels()) / static_cast<double>(res.dots))
                             : std::max(input.width, input.height);
  res.sigma = opt.sigma > 0 ? opt.sigma : res.dot_spacing;
  std::vector<Vec2> centres;
  centres.reserve(blobs.size());
  for (const auto& b : blobs) centres.push_back({b.x, b.y});
  res.mark_spacing = mark_spacing(centres);

  // Blurred SSIM at input resolution.
  cv::Mat dr;
  cv::resize(dr_full, dr, in.size(), 0, 0, cv::INTER_AREA);
  cv::Mat bi, bd;
  gaussian_blur_bounded(in, bi, res.sigma, cv::BORDER_DEFAULT);
  gaussian_blur_bounded(dr, bd, res.sigma, cv::BORDER_DEFAULT);
  res.ssim_blurred = ssim_mat(bi, bd);

  // Strong edges of the input: Canny on a lightly smoothed copy.
  cv::Mat smooth, edges;
  cv::GaussianBlur(in, smooth, cv::Size(0, 0), 1.0);
  cv::Canny(smooth, edges, 60, 150, 3, true);
  cv::Mat not_edge = edges == 0, dist, nearest;
  cv::distanceTransform(not_edge, dist, nearest, cv::DIST_L2, cv::DIST_MASK_PRECISE, cv::DIST_LABEL_PIXEL);
  // Map each label to its edge pixel's coordinates to read the level across the edge.
  std::vector<cv::Point> label_pt(static_cast<size_t>(cv::countNonZero(edges)) + 1);
  for (int y = 0; y < edges.rows; ++y)
    for (int x = 0; x < edges.cols; ++x)
      if (edges.at<uint8_t>(y, x)) label_pt[static_cast<size_t>(nearest.at<int>(y, x))] = {x, y};
  for (const auto& b : blobs) {
    int x = std::clamp(static_cast<int>(b.x), 0, in.cols - 1), y = std::clamp(static_cast<int>(b.y), 0, in.rows - 1);
    if (label_pt.size() <= 1 || dist.at<float>(y, x) > opt.edge_distance) continue;
    ++res.dots_near_edges;
    cv::Point e = label_pt[static_cast<size_t>(nearest.at<int>(y, x))];
    double mid = smooth.at<uint8_t>(e.y, e.x);  // the level half-way across the edge
    double here = in.at<uint8_t>(y, x);
    if (b.dark ? here > mid : here < mid) ++res.spilled;
  }
  res.edge_spill = res.dots_near_edges ? static_cast<double>(res.spilled) / static_cast<double>(res.dots_near_edges) : 0;
  return res;
}

}  // namespace stipplot
