#include "eval/color_difference.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "util/error.hpp"

namespace stipplot {

namespace {
constexpr double kPi = 3.14159265358979323846;
double deg(double rad) { return rad * 180.0 / kPi; }
double rad(double deg) { return deg * kPi / 180.0; }
}  // namespace

double ciede2000(const Lab& x, const Lab& y) {
  const double pow25_7 = 6103515625.0;  // 25^7
  const double c1 = std::hypot(x.a, x.b), c2 = std::hypot(y.a, y.b);
  const double cbar7 = std::pow(0.5 * (c1 + c2), 7.0);
  const double g = 0.5 * (1.0 - std::sqrt(cbar7 / (cbar7 + pow25_7)));
  const double a1 = (1 + g) * x.a, a2 = (1 + g) * y.a;
  const double C1 = std::hypot(a1, x.b), C2 = std::hypot(a2, y.b);
  auto hue = [](double b, double a) {
    if (a == 0 && b == 0) return 0.0;
    double h = deg(std::atan2(b, a));
    return h < 0 ? h + 360.0 : h;
  };
  const double h1 = hue(x.b, a1), h2 = hue(y.b, a2);
  const double dL = y.L - x.L, dC = C2 - C1;
  double dh = 0;
  if (C1 * C2 != 0) {
    dh = h2 - h1;
    if (dh > 180) dh -= 360;
    else if (dh < -180) dh += 360;
  }
  const double dH = 2 * std::sqrt(C1 * C2) * std::sin(rad(dh / 2));
  const double Lbar = 0.5 * (x.L + y.L), Cbar = 0.5 * (C1 + C2);
  double hbar = h1 + h2;
  if (C1 * C2 != 0) {
    if (std::abs(h1 - h2) > 180) hbar += (hbar < 360) ? 360 : -360;
    hbar *= 0.5;
  }
  const double T = 1 - 0.17 * std::cos(rad(hbar - 30)) + 0.24 * std::cos(rad(2 * hbar)) +
                   0.32 * std::cos(rad(3 * hbar + 6)) - 0.20 * std::cos(rad(4 * hbar - 63));
  const double dtheta = 30 * std::exp(-std::pow((hbar - 275) / 25, 2));
  const double cbar7p = std::pow(Cbar, 7.0);
  const double Rc = 2 * std::sqrt(cbar7p / (cbar7p + pow25_7));
  const double l50 = (Lbar - 50) * (Lbar - 50);
  const double Sl = 1 + 0.015 * l50 / std::sqrt(20 + l50);
  const double Sc = 1 + 0.045 * Cbar;
  const double Sh = 1 + 0.015 * Cbar * T;
  const double Rt = -std::sin(rad(2 * dtheta)) * Rc;
  const double tl = dL / Sl, tc = dC / Sc, th = dH / Sh;
  return std::sqrt(tl * tl + tc * tc + th * th + Rt * tc * th);
}

namespace {
cv::Mat lab_blurred(const cv::Mat& rgb8, double sigma) {
  cv::Mat f;
  rgb8.convertTo(f, CV_32FC3, 1.0 / 255);
  if (sigma > 0) cv::GaussianBlur(f, f, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE);
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
