#include "methods/pointillism/lab.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace stipplot::lab {

namespace {

// D65 reference white (as OpenCV uses), Y = 1.
constexpr double kXn = 0.950456, kZn = 1.088754;
constexpr double kEps = 216.0 / 24389.0, kKappa = 24389.0 / 27.0;

double srgb_decode(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }
double srgb_encode(double v) {
  // Odd extension so out-of-gamut negatives stay negative (callers test the range).
  if (v < 0) return -srgb_encode(-v);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
}

const std::array<double, 256>& decode_table() {
  static const std::array<double, 256> t = [] {
    std::array<double, 256> a{};
    for (int i = 0; i < 256; ++i) a[i] = srgb_decode(i / 255.0);
    return a;
  }();
  return t;
}

double f_lab(double t) { return t > kEps ? std::cbrt(t) : (kKappa * t + 16) / 116; }
double f_inv(double f) {
  const double f3 = f * f * f;
  return f3 > kEps ? f3 : (116 * f - 16) / kKappa;
}


}  // namespace

Lab from_srgb(Color c) {
  const auto& t = decode_table();
  const double r = t[c.r], g = t[c.g], b = t[c.b];
  const double X = 0.412453 * r + 0.357580 * g + 0.180423 * b;
  const double Y = 0.212671 * r + 0.715160 * g + 0.072169 * b;
  const double Z = 0.019334 * r + 0.119193 * g + 0.950227 * b;
  const double fx = f_lab(X / kXn), fy = f_lab(Y), fz = f_lab(Z / kZn);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

void to_srgb_unclipped(const Lab& lab, double rgb[3]) {
  const double fy = (lab.L + 16) / 116;
  const double fx = fy + lab.a / 500, fz = fy - lab.b / 200;
  const double X = kXn * f_inv(fx), Y = f_inv(fy), Z = kZn * f_inv(fz);
  // Inverse of the matrix above.
  const double r = 3.240479 * X - 1.537150 * Y - 0.498535 * Z;
  const double g = -0.969256 * X + 1.875992 * Y + 0.041556 * Z;
  const double b = 0.055648 * X - 0.204043 * Y + 1.057311 * Z;
  rgb[0] = srgb_encode(r);
  rgb[1] = srgb_encode(g);
  rgb[2] = srgb_encode(b);
}

bool in_gamut(const Lab& lab, double eps) {
  double rgb[3];
  to_srgb_unclipped(lab, rgb);
  for (double v : rgb)
    if (!(v >= -eps && v <= 1 + eps)) return false;
  return true;
}

Color to_srgb(const Lab& in) {
  Lab lab{std::clamp(in.L, 0.0, 100.0), in.a, in.b};
  if (!in_gamut(lab, 0.5 / 255)) {
    // Keep L* and hue, shrink chroma until the colour fits (L* in [0,100] always has
    // the neutral grey in gamut, so the bisection has a valid lower end).
    double lo = 0, hi = 1;
    for (int i = 0; i < 24; ++i) {
      const double mid = (lo + hi) / 2;
      (in_gamut({lab.L, lab.a * mid, lab.b * mid}, 0.5 / 255) ? lo : hi) = mid;
    }
    lab.a *= lo;
    lab.b *= lo;
  }
  double rgb[3];
  to_srgb_unclipped(lab, rgb);
  auto q = [](double v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255)); };
  return {q(rgb[0]), q(rgb[1]), q(rgb[2])};
}

double max_chroma(double L, double hue, double tol) {
  const double ca = std::cos(hue), sb = std::sin(hue);
  if (!in_gamut({L, 0, 0})) return 0;
  double lo = 0, hi = 200;  // sRGB chroma never exceeds ~134
  while (hi - lo > tol) {
    const double mid = (lo + hi) / 2;
    (in_gamut({L, mid * ca, mid * sb}) ? lo : hi) = mid;
  }
  return lo;
}


}  // namespace stipplot::lab
