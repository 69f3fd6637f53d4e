#include "methods/hatch/hatch.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "eval/bounded_blur.hpp"
#include "methods/hatch/hatch_lines.hpp"
#include "methods/working_grid.hpp"
#include "util/error.hpp"

namespace stipplot::hatch {

void HatchParams::validate() const {
  if (levels < 2 || levels > kMaxLevels)
    throw UserError("--levels must be between 2 and " + std::to_string(kMaxLevels) + " (tone bands, white included), got " +
                    std::to_string(levels));
  require_range("--spacing (mm)", spacing_mm, 0, 100);
  require_range("spacing scale", spacing_scale, 1, 1e6);
  require_range("--blur (mm)", blur_mm, 0, 100);
  require_range("--angle (degrees)", angle_deg, -360, 360);
  require_range("--link (mm)", link_mm, 0, 1000);
}

ToneMap tone_map(const Image& image, const HatchParams& p, const Placement& placement) {
  const PageTransform tf = placement.transform(image.width, image.height);
  // A cell of one pen width: the lines are clipped to the bands at a pen's precision.
  const WorkingGrid grid = make_working_grid(image, tf, placement.pen_width_mm, 8'000'000);
  ToneMap t;
  t.width = grid.image.width, t.height = grid.image.height;
  t.cell_mm = grid.cell_mm, t.origin_mm = grid.origin_mm;
  std::vector<uint8_t> luma = grid.image.luma();
  cv::Mat g(t.height, t.width, CV_8U, luma.data()), f;
  g.convertTo(f, CV_32F, 1.0 / 255);
  // Blurred on paper, so the bands are shapes a pen can hatch, not the photo's grain.
  if (p.blur_mm > 0) gaussian_blur_rows(f, f, p.blur_mm / t.cell_mm, cv::BORDER_REPLICATE);
  const size_t n = static_cast<size_t>(t.width) * static_cast<size_t>(t.height);
  const int top = p.levels - 1;
  t.band.resize(n);
  std::vector<double> sum(static_cast<size_t>(p.levels), 0), count(static_cast<size_t>(p.levels), 0);
  const float* v = f.ptr<float>();
  for (size_t i = 0; i < n; ++i) {
    const double d = std::clamp(1.0 - double(v[i]), 0.0, 1.0);
    const int b = std::clamp(static_cast<int>(std::lround(d * top)), 0, top);
    t.band[i] = static_cast<uint8_t>(b);
    sum[static_cast<size_t>(b)] += d, count[static_cast<size_t>(b)] += 1;
  }
  const double cell_area = t.cell_mm * t.cell_mm;
  for (int b = 0; b <= top; ++b) {
    const size_t k = static_cast<size_t>(b);
    t.area_mm2.push_back(count[k] * cell_area);
    t.darkness.push_back(count[k] > 0 ? sum[k] / count[k] : double(b) / top);
  }
  return t;
}

namespace {
double pen_darkness(const Pen& pen) { return 1.0 - luma601(pen.color.r, pen.color.g, pen.color.b) / 255.0; }

bool neutral(const Pen& pen) {
  const Color c = pen.color;
  return std::max({c.r, c.g, c.b}) - std::min({c.r, c.g, c.b}) <= 48;
}

// The pens light to dark, too light ones (which cannot lay tone) left out; a palette's
// greys and blacks only, when it has any (a tone drawn in yellow and violet is no tone).
std::vector<Pen> tone_pens(const HatchParams& p, double pen_width_mm) {
  if (p.pens.empty()) return {Pen{"black", colors::black, pen_width_mm}};
  const bool any_neutral = std::any_of(p.pens.begin(), p.pens.end(), [](const Pen& pen) {
    return neutral(pen) && pen_darkness(pen) >= 0.05;
  });
  std::vector<Pen> pens;
  for (const Pen& pen : p.pens)
    if (pen_darkness(pen) >= 0.05 && (neutral(pen) || !any_neutral)) pens.push_back(pen);
  if (pens.empty()) throw UserError("--pens: every pen is too light to lay tone on white paper");
  std::stable_sort(pens.begin(), pens.end(), [](const Pen& a, const Pen& b) { return pen_darkness(a) < pen_darkness(b); });
  return pens;
}

// Line coverage of one direction at spacing x scale (a pen wider than the gap fills it).
double coverage(const Direction& d, double scale) {
  return d.spacing_mm > 0 ? std::min(1.0, d.pen.width_mm / (d.spacing_mm * scale)) : 0;
}
}  // namespace

std::vector<Direction> directions(const ToneMap& t, const HatchParams& p, double pen_width_mm) {
  // Each new direction crosses the ones before it as widely as it can.
  static constexpr double kOffsets[kMaxLevels - 1] = {0, 90, -45, 45, -22.5, 67.5, 22.5, -67.5};
  const std::vector<Pen> pens = tone_pens(p, pen_width_mm);
  const size_t count = static_cast<size_t>(p.levels - 1);
  std::vector<Direction> dirs;
  double reached = 0, target = 0;
  for (size_t j = 0; j < count; ++j) {
    Direction d;
    d.angle_deg = p.angle_deg + kOffsets[j];
    d.pen = pens[j * pens.size() / count];
    d.pen_darkness = pen_darkness(d.pen);
    target = std::max(target, t.darkness[j + 1]);  // darker bands never get less ink
    if (target > reached + 1e-4) {
      // This direction's lines must take the paper left from (1 - reached) to (1 - target).
      const double keep = (1 - target) / (1 - reached);
      const double cov = std::min(1.0, (1 - keep) / d.pen_darkness);
      d.spacing_mm = std::max({d.pen.width_mm / cov, d.pen.width_mm, p.spacing_mm});
      reached = 1 - (1 - reached) * (1 - d.pen_darkness * coverage(d, 1));
    }
    dirs.push_back(d);
  }
  return dirs;
}

double band_darkness(const std::vector<Direction>& dirs, size_t band, double scale) {
  double paper = 1;
  for (size_t j = 0; j < band && j < dirs.size(); ++j) paper *= 1 - dirs[j].pen_darkness * coverage(dirs[j], scale);
  return 1 - paper;
}

double mean_darkness(const ToneMap& t, const std::vector<Direction>& dirs, double scale) {
  double ink = 0, area = 0;
  for (size_t b = 0; b < t.area_mm2.size(); ++b) ink += t.area_mm2[b] * band_darkness(dirs, b, scale), area += t.area_mm2[b];
  return area > 0 ? ink / area : 0;
}

double photo_darkness(const ToneMap& t) {
  double ink = 0, area = 0;
  for (size_t b = 0; b < t.area_mm2.size(); ++b) ink += t.area_mm2[b] * t.darkness[b], area += t.area_mm2[b];
  return area > 0 ? ink / area : 0;
}

namespace {
Vec2 to_page(const ToneMap& t, double cx, double cy) { return {t.origin_mm.x + cx * t.cell_mm, t.origin_mm.y + cy * t.cell_mm}; }

bool on_border(const cv::Point& q, int w, int h) { return q.x == 0 || q.y == 0 || q.x == w - 1 || q.y == h - 1; }

// The boundaries of a region as open polylines on the page, cut where they run along the
// grid's border (the image's edge is no edge of the photo). O(cells).
std::vector<Polyline> trace_contours(const ToneMap& t, const Mask& m) {
  cv::Mat img(m.height, m.width, CV_8U, const_cast<uint8_t*>(m.in.data()));
  std::vector<std::vector<cv::Point>> found;
  cv::findContours(img.clone(), found, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
  std::vector<Polyline> out;
  auto flush = [&](Polyline& pl) {
    double len = 0;
    for (size_t i = 1; i < pl.pts.size(); ++i) len += std::hypot(pl.pts[i].x - pl.pts[i - 1].x, pl.pts[i].y - pl.pts[i - 1].y);
    if (len >= 1.0) out.push_back(std::move(pl));  // shorter ones are specks, not shapes
    pl.pts.clear();
  };
  for (const auto& c : found) {
    std::vector<cv::Point> s;
    cv::approxPolyDP(c, s, 0.7, true);
    if (s.size() < 2) continue;
    s.push_back(s.front());  // closed
    Polyline pl;
    for (size_t i = 0; i < s.size(); ++i) {
      const bool cut = i > 0 && on_border(s[i - 1], m.width, m.height) && on_border(s[i], m.width, m.height);
      if (cut) flush(pl);
      pl.pts.push_back(to_page(t, s[i].x + 0.5, s[i].y + 0.5));
    }
    flush(pl);
  }
  return out;
}
}  // namespace

Drawing hatch_lines(const ToneMap& t, const std::vector<Direction>& dirs, const HatchParams& p, const Page& page) {
  Drawing d;
  d.page = page;
  Mask m{t.width, t.height, std::vector<uint8_t>(t.band.size())};
  for (size_t j = 0; j < dirs.size(); ++j) {
    const Direction& dir = dirs[j];
    for (size_t i = 0; i < t.band.size(); ++i) m.in[i] = t.band[i] > j ? 1 : 0;
    Layer layer;
    layer.pen = dir.pen;
    if (dir.spacing_mm > 0) {
      const double s = dir.spacing_mm * p.spacing_scale;
      const LineSet set{dir.angle_deg, s / t.cell_mm, std::max(p.link_mm, 1.5 * s) / t.cell_mm};
      for (auto& stroke : hatch_mask(m, set)) {
        Polyline pl;
        pl.pts.reserve(stroke.size());
        for (Vec2 q : stroke) pl.pts.push_back(to_page(t, q.x, q.y));
        layer.lines.push_back(std::move(pl));
      }
    }
    if (p.contours)
      for (Polyline& pl : trace_contours(t, m)) layer.lines.push_back(std::move(pl));
    if (layer.primitive_count() > 0) d.layers.push_back(std::move(layer));
  }
  return d;
}

Drawing hatch_drawing(const Image& image, const HatchParams& p, const Placement& placement) {
  p.validate();
  placement.validate();
  if (image.pixels() == 0) throw UserError("image has no pixels");
  const ToneMap t = tone_map(image, p, placement);
  const PageTransform tf = placement.transform(image.width, image.height);
  return hatch_lines(t, directions(t, p, placement.pen_width_mm), p, Page{tf.page_w(), tf.page_h()});
}

}  // namespace stipplot::hatch
