#include "eval/view.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "eval/bounded_blur.hpp"
#include "eval/lab.hpp"
#include "preview/preview.hpp"
#include "util/error.hpp"
#include "util/threads.hpp"
#include "util/units.hpp"

namespace stipplot {

namespace {

// skimage's SSIM window, 7 px at measure.py's 10 px/mm, kept as a width on paper; its
// sample-covariance factor stays 49/48 at every resolution.
constexpr double kWindowMm = 0.7;
constexpr double kCovNorm = 49.0 / 48.0;
// The blurs --view-sigma accepts: below a micrometre is no blur, beyond 10 cm no drawing.
constexpr double kLeastSigmaMm = 1e-3, kMostSigmaMm = 100;

// Pixel boxes on the page grid.
struct Box {
  int x0, y0, x1, y1;  // [x0, x1) x [y0, y1)
  int w() const { return x1 - x0; }
  int h() const { return y1 - y0; }
};

// Rec. 709 weights on the sRGB codes, 0..1 (skimage.color.rgb2gray).
double grey709(const uint8_t* p) { return (0.2125 * p[0] + 0.7154 * p[1] + 0.0721 * p[2]) / 255.0; }

// The drawing over `r`: channel planes (grey, or R G B) as darkness 1 - v, so that a
// zero border is white paper.
std::vector<cv::Mat> drawn_darkness(const Image& page, const Box& r, bool colour) {
  std::vector<cv::Mat> m(colour ? 4 : 1);
  for (auto& c : m) c = cv::Mat(r.h(), r.w(), CV_64F);
#pragma omp parallel for schedule(static) num_threads(thread_count()) if (r.h() >= 64)
  for (int y = 0; y < r.h(); ++y)
    for (int x = 0; x < r.w(); ++x) {
      const uint8_t* p = &page.rgb[(static_cast<size_t>(y + r.y0) * page.width + (x + r.x0)) * 3];
      m[0].at<double>(y, x) = 1 - grey709(p);
      for (size_t c = 1; c < m.size(); ++c) m[c].at<double>(y, x) = 1 - p[c - 1] / 255.0;
    }
  return m;
}

// The photo laid on the page grid over `r` (bilinear at pixel centres, edges clamped, white
// outside its rectangle `rect` in page px), as darkness planes like drawn_darkness.
std::vector<cv::Mat> photo_darkness(const Image& photo, const cv::Rect2d& rect, const Box& r, bool colour) {
  std::vector<cv::Mat> m(colour ? 4 : 1);
  for (auto& c : m) c = cv::Mat(r.h(), r.w(), CV_64F, cv::Scalar(0));
  const int w = photo.width, h = photo.height;
  auto at = [&](int x, int y) { return &photo.rgb[(static_cast<size_t>(y) * w + x) * 3]; };
#pragma omp parallel for schedule(static) num_threads(thread_count()) if (r.h() >= 64)
  for (int y = 0; y < r.h(); ++y) {
    const double cy = y + r.y0 + 0.5;
    if (cy < rect.y || cy >= rect.y + rect.height) continue;
    const double v = std::clamp((cy - rect.y) / rect.height * h - 0.5, 0.0, h - 1.0);
    const int y0 = static_cast<int>(v), y1 = std::min(y0 + 1, h - 1);
    const double fy = v - y0;
    for (int x = 0; x < r.w(); ++x) {
      const double cx = x + r.x0 + 0.5;
      if (cx < rect.x || cx >= rect.x + rect.width) continue;
      const double u = std::clamp((cx - rect.x) / rect.width * w - 0.5, 0.0, w - 1.0);
      const int x0 = static_cast<int>(u), x1 = std::min(x0 + 1, w - 1);
      const double fx = u - x0;
      const uint8_t *a = at(x0, y0), *b = at(x1, y0), *c = at(x0, y1), *d = at(x1, y1);
      auto mix = [&](double va, double vb, double vc, double vd) {
        return (1 - fy) * ((1 - fx) * va + fx * vb) + fy * ((1 - fx) * vc + fx * vd);
      };
      m[0].at<double>(y, x) = 1 - mix(grey709(a), grey709(b), grey709(c), grey709(d));
      for (size_t k = 1; k < m.size(); ++k)
        m[k].at<double>(y, x) = 1 - mix(a[k - 1], b[k - 1], c[k - 1], d[k - 1]) / 255.0;
    }
  }
  return m;
}

// A box filter `width_px` wide (fractional end taps: the width is on paper, not in pixels).
cv::Mat box_kernel(double width_px) {
  const double half = std::max(width_px, 1.0) / 2;
  const int r = static_cast<int>(std::ceil(half - 0.5));
  cv::Mat k(2 * r + 1, 1, CV_64F);
  for (int i = -r; i <= r; ++i)
    k.at<double>(i + r) = std::clamp(std::min(i + 0.5, half) - std::max(i - 0.5, -half), 0.0, 1.0);
  return k / cv::sum(k)[0];
}

// f(y) for rows 0..n-1, rows side by side.
template <class F>
void for_rows(int n, F&& f) {
#pragma omp parallel for schedule(static) num_threads(thread_count()) if (n >= 64)
  for (int y = 0; y < n; ++y) f(y);
}

// Sums f(y) over rows 0..n-1 as per-row partial sums added in row order: the same total
// on any thread count.
template <class F>
double sum_rows(int n, F&& f) {
  std::vector<double> row(static_cast<size_t>(std::max(n, 0)));
  for_rows(n, [&](int y) { row[static_cast<size_t>(y)] = f(y); });
  double total = 0;
  for (double v : row) total += v;
  return total;
}

// skimage.metrics.structural_similarity(a, b, data_range=1) with its window in mm. The
// five window means are filtered side by side; the per-pixel formula is one pass over
// the cropped map (no temporaries: the arithmetic on whole images was half the cost).
double ssim_mm(const cv::Mat& a, const cv::Mat& b, double px_per_mm) {
  const double win = kWindowMm * px_per_mm;
  const cv::Mat k = box_kernel(win);
  cv::Mat in[5] = {a, b, cv::Mat(a.size(), CV_64F), cv::Mat(a.size(), CV_64F), cv::Mat(a.size(), CV_64F)};
  for_rows(a.rows, [&](int y) {
    const double *pa = a.ptr<double>(y), *pb = b.ptr<double>(y);
    double *aa = in[2].ptr<double>(y), *bb = in[3].ptr<double>(y), *ab = in[4].ptr<double>(y);
    for (int x = 0; x < a.cols; ++x) aa[x] = pa[x] * pa[x], bb[x] = pb[x] * pb[x], ab[x] = pa[x] * pb[x];
  });
  cv::Mat mean[5];
#pragma omp parallel for schedule(dynamic, 1) num_threads(thread_count())
  for (int i = 0; i < 5; ++i) cv::sepFilter2D(in[i], mean[i], CV_64F, k, k, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
  const double c1 = 1e-4, c2 = 9e-4;  // (0.01 R)^2, (0.03 R)^2, R = 1
  const int pad = std::min({static_cast<int>(win / 2), (a.cols - 1) / 2, (a.rows - 1) / 2});
  const int x0 = pad, x1 = a.cols - pad, rows = a.rows - 2 * pad;
  const double total = sum_rows(rows, [&](int r) {
    const int y = r + pad;
    const double *ua = mean[0].ptr<double>(y), *ub = mean[1].ptr<double>(y), *uaa = mean[2].ptr<double>(y),
                 *ubb = mean[3].ptr<double>(y), *uab = mean[4].ptr<double>(y);
    double sum = 0;
    for (int x = x0; x < x1; ++x) {
      const double va = kCovNorm * (uaa[x] - ua[x] * ua[x]), vb = kCovNorm * (ubb[x] - ub[x] * ub[x]);
      const double vab = kCovNorm * (uab[x] - ua[x] * ub[x]);
      sum += ((2 * ua[x] * ub[x] + c1) * (2 * vab + c2)) / ((ua[x] * ua[x] + ub[x] * ub[x] + c1) * (va + vb + c2));
    }
    return sum;
  });
  return total / (static_cast<double>(rows) * (x1 - x0));
}

// Pearson r, mean |a - b| and the means of two tone images (1 = white), in two passes.
void tone_figures(const cv::Mat& a, const cv::Mat& b, ViewScore& v) {
  const double n = static_cast<double>(a.total());
  double sa = 0, sb = 0;
  auto mean_of = [&](const cv::Mat& m) {
    return sum_rows(m.rows, [&](int y) {
      const double* p = m.ptr<double>(y);
      double s = 0;
      for (int x = 0; x < m.cols; ++x) s += p[x];
      return s;
    }) / n;
  };
  const double mean_a = mean_of(a), mean_b = mean_of(b);
  double err = 0, cov = 0;
  std::vector<double> row_err(static_cast<size_t>(a.rows)), row_cov(row_err.size()), row_va(row_err.size()),
      row_vb(row_err.size());
  for_rows(a.rows, [&](int y) {
    const double *p = a.ptr<double>(y), *q = b.ptr<double>(y);
    double e = 0, c = 0, va = 0, vb = 0;
    for (int x = 0; x < a.cols; ++x) {
      const double da = p[x] - mean_a, db = q[x] - mean_b;
      e += std::abs(p[x] - q[x]);
      c += da * db;
      va += da * da;
      vb += db * db;
    }
    row_err[static_cast<size_t>(y)] = e, row_cov[static_cast<size_t>(y)] = c;
    row_va[static_cast<size_t>(y)] = va, row_vb[static_cast<size_t>(y)] = vb;
  });
  for (size_t y = 0; y < row_err.size(); ++y) err += row_err[y], cov += row_cov[y], sa += row_va[y], sb += row_vb[y];
  v.mean_photo = mean_a;
  v.mean_drawn = mean_b;
  v.tone_err = err / n;
  const double sd_a = std::sqrt(sa / n), sd_b = std::sqrt(sb / n);
  // A flat image has no tone to follow: r is undefined, reported as 0 (as measure.py).
  v.tone_r = sd_a > 1e-12 && sd_b > 1e-12 ? (cov / n) / (sd_a * sd_b) : 0;
}

// Mean CIEDE2000 of two blurred colour images given as R, G, B darkness planes.
double mean_delta_e(const std::vector<cv::Mat>& a, const std::vector<cv::Mat>& b, const Box& crop) {
  auto lab = [&](const std::vector<cv::Mat>& d) {
    std::vector<cv::Mat> rgb;
    for (size_t c = 1; c < 4; ++c) {
      cv::Mat f;
      cv::Mat(1 - d[c](cv::Rect(crop.x0, crop.y0, crop.w(), crop.h()))).convertTo(f, CV_32F);
      rgb.push_back(f);
    }
    cv::Mat m, l;
    cv::merge(rgb, m);
    cv::cvtColor(m, l, cv::COLOR_RGB2Lab);
    return l;
  };
  const cv::Mat la = lab(a), lb = lab(b);
  double total = 0;
  for (int y = 0; y < la.rows; ++y)
    for (int x = 0; x < la.cols; ++x) {
      const cv::Vec3f p = la.at<cv::Vec3f>(y, x), q = lb.at<cv::Vec3f>(y, x);
      total += ciede2000({p[0], p[1], p[2]}, {q[0], q[1], q[2]});
    }
  return total / static_cast<double>(la.total());
}

// The render at no more than 10 px/mm (measure.py's; 5 px a sigma for small sigmas):
// finer adds nothing after the blur and costs its square. `drawn` itself when fine enough.
const Image& finest_needed(const Image& drawn, const PageTransform& tf, double sigma_mm, Image& store) {
  const double sx = drawn.width / tf.page_w(), sy = drawn.height / tf.page_h();
  if (std::abs(sx - sy) > 0.02 * std::max(sx, sy))
    throw UserError("the drawing's render does not have the page's shape; pass the --page, --margin and --landscape "
                    "it was made with");
  const double most = std::max(10.0, 5 / sigma_mm);
  if (sx <= most) return drawn;
  const cv::Size to(std::max(1, static_cast<int>(std::ceil(tf.page_w() * most))),
                    std::max(1, static_cast<int>(std::ceil(tf.page_h() * most))));
  cv::Mat small;
  cv::resize(cv::Mat(drawn.height, drawn.width, CV_8UC3, const_cast<uint8_t*>(drawn.rgb.data())), small, to, 0, 0,
             cv::INTER_AREA);
  store.width = small.cols;
  store.height = small.rows;
  store.rgb.assign(small.data, small.data + small.total() * 3);
  return store;
}

}  // namespace

ViewScore view_score(const Image& photo, const PageTransform& tf, const Image& drawn, const ViewOptions& opt) {
  require_range("view sigma (mm)", opt.sigma_mm, kLeastSigmaMm, kMostSigmaMm);
  if (photo.pixels() == 0 || drawn.pixels() == 0) throw UserError("view measure: empty image");
  Image store;
  const Image& page = finest_needed(drawn, tf, opt.sigma_mm, store);
  const double ppmm = page.width / tf.page_w();
  // Pixels are square within 2 % (finest_needed checks); a degenerate page keeps its own height.
  const double ppmm_y = page.height / tf.page_h();
  const cv::Rect2d rect(tf.origin_x() * ppmm, tf.origin_y() * ppmm_y, photo.width * tf.mm_per_px() * ppmm,
                        photo.height * tf.mm_per_px() * ppmm_y);
  // measure.py's crop: the pixels wholly inside the photo's rectangle.
  Box crop{static_cast<int>(std::ceil(rect.x - 1e-6)), static_cast<int>(std::ceil(rect.y - 1e-6)),
           static_cast<int>(std::floor(rect.br().x + 1e-6)), static_cast<int>(std::floor(rect.br().y + 1e-6))};
  // A rectangle thinner than a pixel (a one-pixel-tall photo) is the pixel row it lies on.
  auto at_least_one = [](int& lo, int& hi, double at, int n) {
    lo = std::max(lo, 0), hi = std::min(hi, n);
    if (hi <= lo) lo = std::clamp(static_cast<int>(at), 0, n - 1), hi = lo + 1;
  };
  at_least_one(crop.x0, crop.x1, rect.x, page.width);
  at_least_one(crop.y0, crop.y1, rect.y, page.height);
  // Blurring the rectangle needs its surroundings out to the kernel's reach (4 sigma);
  // beyond the page it is white paper, a zero darkness border.
  const double sigma_px = opt.sigma_mm * ppmm;
  const int reach = static_cast<int>(std::ceil(4 * sigma_px)) + 1;
  const Box r{std::max(crop.x0 - reach, 0), std::max(crop.y0 - reach, 0), std::min(crop.x1 + reach, page.width),
              std::min(crop.y1 + reach, page.height)};
  std::vector<cv::Mat> pa = photo_darkness(photo, rect, r, opt.colour), pb = drawn_darkness(page, r, opt.colour);
  // Every plane blurred on its own, side by side.
  std::vector<cv::Mat*> planes;
  for (auto* ps : {&pa, &pb})
    for (cv::Mat& m : *ps) planes.push_back(&m);
#pragma omp parallel for schedule(dynamic, 1) num_threads(thread_count())
  for (size_t i = 0; i < planes.size(); ++i) gaussian_blur_bounded(planes[i]->clone(), *planes[i], sigma_px, cv::BORDER_CONSTANT);
  const Box in_r{crop.x0 - r.x0, crop.y0 - r.y0, crop.x1 - r.x0, crop.y1 - r.y0};
  const cv::Rect cr(in_r.x0, in_r.y0, in_r.w(), in_r.h());
  const cv::Mat a = 1 - pa[0](cr), b = 1 - pb[0](cr);
  ViewScore v;
  v.sigma_mm = opt.sigma_mm;
  v.px_per_mm = ppmm;
  v.ssim = ssim_mm(a, b, ppmm);
  tone_figures(a, b, v);
  if (opt.colour) v.delta_e = mean_delta_e(pa, pb, in_r);
  return v;
}

ViewScore view_score_of_plan(const Image& photo, const PageTransform& tf, const Plan& plan, const ViewOptions& opt,
                             double px_per_mm) {
  PreviewOptions po;
  po.dpi = px_per_mm * 25.4;
  return view_score(photo, tf, render_plan(plan, po), opt);
}

ViewScore view_score_of_drawing(const Image& photo, const PageTransform& tf, const Drawing& drawing,
                                const ViewOptions& opt, double px_per_mm) {
  PreviewOptions po;
  po.dpi = px_per_mm * 25.4;
  return view_score(photo, tf, render_preview(drawing, po), opt);
}

double view_px_per_mm(double page_w_mm, double page_h_mm) {
  return std::min(10.0, std::sqrt(25e6 / std::max(page_w_mm * page_h_mm, 1e-9)));
}

double parse_view_sigma_mm(std::string_view text, const char* option) {
  double v = 0;
  std::string unit;
  const std::string o(option);
  if (!split_number_unit(text, v, unit))
    throw UserError(o + " must be a length with its unit (1mm, 0.5mm, 0.1cm), not '" + std::string(text) + "'");
  if (unit.empty())
    throw UserError(o + " needs a unit (1mm, 0.5mm, 0.1cm): '" + std::string(text) +
                    "' could be millimetres or pixels");
  const double mm = v * mm_per_unit(unit);
  if (mm_per_unit(unit) == 0) throw UserError(o + ": unknown unit '" + unit + "' (mm, cm, in, pt, px)");
  if (!std::isfinite(mm) || mm < kLeastSigmaMm || mm > kMostSigmaMm)
    throw UserError(o + " must be more than 0 (at least 0.001 mm) and at most 100 mm, not '" + std::string(text) + "'");
  return mm;
}

}  // namespace stipplot
