#pragma once
// Affine maps of the plane, as SVG writes them: x' = a x + c y + e, y' = b x + d y + f
// (matrix(a b c d e f)). The SVG reader composes its transforms with them and the layout
// stage places drawings on the sheet with them.
#include <algorithm>
#include <cmath>

#include "geometry/drawing.hpp"

namespace stipplot {

struct Affine {
  double a = 1, b = 0, c = 0, d = 1, e = 0, f = 0;

  Vec2 apply(Vec2 p) const { return {a * p.x + c * p.y + e, b * p.x + d * p.y + f}; }
  Affine operator*(const Affine& o) const {  // this after o
    return {a * o.a + c * o.b, b * o.a + d * o.b, a * o.c + c * o.d,
            b * o.c + d * o.d, a * o.e + c * o.f + e, b * o.e + d * o.f + f};
  }
  double det() const { return a * d - b * c; }
  // The map back (det must not be 0).
  Affine inverse() const {
    const double k = 1 / det();
    return {d * k, -b * k, -c * k, a * k, (c * f - d * e) * k, (b * e - a * f) * k};
  }
  // Largest stretch of a unit vector (largest singular value).
  double max_scale() const {
    double p = (a * a + b * b + c * c + d * d) / 2, q = std::sqrt(std::max(0.0, p * p - det() * det()));
    return std::sqrt(p + q);
  }
  // Rotation, uniform scale and possibly a reflection: circles stay circles.
  bool is_similarity() const {
    double tol = 1e-9 * (std::fabs(a) + std::fabs(b) + std::fabs(c) + std::fabs(d));
    return (std::fabs(a - d) <= tol && std::fabs(b + c) <= tol) || (std::fabs(a + d) <= tol && std::fabs(b - c) <= tol);
  }

  static Affine translate(double tx, double ty) { return {1, 0, 0, 1, tx, ty}; }
  static Affine scale(double s) { return {s, 0, 0, s, 0, 0}; }
  // Clockwise on a y-down page (SVG's rotate(deg)). Multiples of 90 degrees are exact.
  static Affine rotate_degrees(double deg) {
    const double q = std::round(deg / 90);
    double cs, sn;
    if (std::fabs(deg - 90 * q) < 1e-12) {
      const int k = ((static_cast<int>(std::fmod(q, 4.0)) % 4) + 4) % 4;
      static constexpr double kCos[] = {1, 0, -1, 0}, kSin[] = {0, 1, 0, -1};
      cs = kCos[k];
      sn = kSin[k];
    } else {
      const double r = deg * std::acos(-1.0) / 180;
      cs = std::cos(r);
      sn = std::sin(r);
    }
    return {cs, sn, -sn, cs, 0, 0};
  }
};

}  // namespace stipplot
