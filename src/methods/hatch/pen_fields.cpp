#include "methods/hatch/pen_fields.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "methods/hatch/hatch_lines.hpp"

namespace stipplot::hatch {

PenGrid settle_fields(const PenGrid& g, size_t n_pens, double mode_mm) {
  const int W = g.width, H = g.height;
  if (W <= 0 || H <= 0 || n_pens == 0) return g;
  const size_t n = static_cast<size_t>(W) * static_cast<size_t>(H);
  const double cell = g.cell_mm;
  // The mode over a box of side 2 mode_mm: per pen (and the paper) a box-filtered count.
  const int R = std::max(1, static_cast<int>(std::lround(mode_mm / cell)));
  std::vector<float> top(n, -1.0f);
  std::vector<uint8_t> mode(n, PenGrid::kPaper);
  cv::Mat ind(H, W, CV_32F), sum;
  for (size_t k = 0; k <= n_pens; ++k) {
    const uint8_t id = k == n_pens ? PenGrid::kPaper : static_cast<uint8_t>(k);
    bool any = false;
    float* ip = reinterpret_cast<float*>(ind.data);
    for (size_t i = 0; i < n; ++i) {
      const bool in = g.pen[i] == id;
      ip[i] = in ? 1.0f : 0.0f;
      any |= in;
    }
    if (!any) continue;
    cv::boxFilter(ind, sum, CV_32F, cv::Size(2 * R + 1, 2 * R + 1), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
    const float* sp = reinterpret_cast<const float*>(sum.data);
    for (size_t i = 0; i < n; ++i)
      if (sp[i] > top[i]) top[i] = sp[i], mode[i] = id;
  }
  PenGrid settled = g;
  settled.pen = std::move(mode);
  return settled;
}

void hatch_fields(const PenGrid& g, size_t n_pens, double pen_mm, double coverage, std::vector<Layer>& layers) {
  const int W = g.width, H = g.height;
  if (W <= 0 || H <= 0 || n_pens == 0) return;
  const size_t n = static_cast<size_t>(W) * static_cast<size_t>(H);
  const double cell = g.cell_mm;
  const std::vector<uint8_t>& mode = g.pen;
  coverage = std::clamp(coverage, 1e-3, 1.0);
  // Directions per cell: the amount in kFieldDirections steps, whatever the coverage, so
  // the lines (and the plot's time) grow with the coverage alone.
  std::vector<uint8_t> dirs(n, 1);
  if (g.amount.size() == n)
    for (size_t i = 0; i < n; ++i)
      dirs[i] = static_cast<uint8_t>(std::clamp(std::lround(g.amount[i] * kFieldDirections), 0L, static_cast<long>(kFieldDirections)));
  Mask mask;
  mask.width = W;
  mask.height = H;
  static constexpr double kAngles[] = {45, 135, 0, 90, 22.5, 112.5, 67.5, 157.5};
  static constexpr double kCross[kFieldDirections] = {0, 90, 45};  // each direction's turn from the pen's angle
  for (size_t k = 0; k < n_pens; ++k) {
    for (int j = 1; j <= kFieldDirections; ++j) {
      mask.in.assign(n, 0);
      bool any = false;
      for (size_t i = 0; i < n; ++i)
        if (mode[i] == k && dirs[i] >= j) mask.in[i] = 1, any = true;
      if (!any) break;
      LineSet set;
      set.angle_deg = kAngles[k % (sizeof kAngles / sizeof kAngles[0])] + kCross[j - 1];
      set.spacing = 0.9 * pen_mm / cell / coverage;
      set.link = std::max(10.0, 1.5 * set.spacing);
      for (auto& line : hatch_mask(mask, set)) {
        Polyline pl;
        pl.pts.reserve(line.size());
        for (const Vec2& v : line) pl.pts.push_back({g.origin_mm.x + v.x * cell, g.origin_mm.y + v.y * cell});
        layers[k].lines.push_back(std::move(pl));
      }
    }
  }
}

void hatch_pen_fields(const PenGrid& grid, size_t n_pens, double pen_mm, double coverage, std::vector<Layer>& layers,
                      double mode_mm) {
  hatch_fields(settle_fields(grid, n_pens, mode_mm), n_pens, pen_mm, coverage, layers);
}

}  // namespace stipplot::hatch
