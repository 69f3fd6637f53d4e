#include "eval/lab.hpp"

#include <algorithm>
#include <array>
#include <cmath>

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

}  // namespace stipplot

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
