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

double deg(double rad) { return rad * 180.0 / M_PI; }
double rad(double d) { return d * M_PI / 180.0; }

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

double delta_e00(const Lab& x, const Lab& y) {
  const double C1ab = std::hypot(x.a, x.b), C2ab = std::hypot(y.a, y.b);
  const double Cbar = (C1ab + C2ab) / 2;
  const double Cbar7 = std::pow(Cbar, 7);
  const double G = 0.5 * (1 - std::sqrt(Cbar7 / (Cbar7 + 6103515625.0)));  // 25^7
  const double a1 = (1 + G) * x.a, a2 = (1 + G) * y.a;
  const double C1 = std::hypot(a1, x.b), C2 = std::hypot(a2, y.b);
  // Hue angles in degrees in [0, 360); zero chroma has hue 0 by convention.
  auto hue = [](double b, double a) {
    if (a == 0 && b == 0) return 0.0;
    double h = deg(std::atan2(b, a));
    return h < 0 ? h + 360 : h;
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
  const double Lbar = (x.L + y.L) / 2, Cpbar = (C1 + C2) / 2;
  double hbar = h1 + h2;
  if (C1 * C2 != 0) {
    if (std::abs(h1 - h2) > 180) hbar += hbar < 360 ? 360 : -360;
    hbar /= 2;
  }
  const double T = 1 - 0.17 * std::cos(rad(hbar - 30)) + 0.24 * std::cos(rad(2 * hbar)) +
                   0.32 * std::cos(rad(3 * hbar + 6)) - 0.20 * std::cos(rad(4 * hbar - 63));
  const double dtheta = 30 * std::exp(-std::pow((hbar - 275) / 25, 2));
  const double Cp7 = std::pow(Cpbar, 7);
  const double RC = 2 * std::sqrt(Cp7 / (Cp7 + 6103515625.0));
  const double L50 = (Lbar - 50) * (Lbar - 50);
  const double SL = 1 + 0.015 * L50 / std::sqrt(20 + L50);
  const double SC = 1 + 0.045 * Cpbar;
  const double SH = 1 + 0.015 * Cpbar * T;
  const double RT = -std::sin(rad(2 * dtheta)) * RC;
  const double tL = dL / SL, tC = dC / SC, tH = dH / SH;
  return std::sqrt(tL * tL + tC * tC + tH * tH + RT * tC * tH);
}

}  // namespace stipplot::lab
