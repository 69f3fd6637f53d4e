#pragma once
// CIE L*a*b* (D65, sRGB primaries) of single colours (dots, pens): conversions, the sRGB
// gamut along a hue ray, and the CIEDE2000 colour difference. Bulk image conversion goes
// through OpenCV (cvtColor, see color_difference.hpp); these must agree with it to well
// under one ΔE.
#include "geometry/color.hpp"

namespace stipplot {

struct Lab {
  double L = 0, a = 0, b = 0;
};

// CIEDE2000 (CIE 142-2001) with kL = kC = kH = 1, following Sharma, Wu & Dalal (2005),
// including their notes on hue wrap-around and zero chroma. O(1).
double ciede2000(const Lab& x, const Lab& y);

}  // namespace stipplot

namespace stipplot::lab {

using Lab = stipplot::Lab;

// sRGB (gamma-encoded, 8 bits) → L*a*b*. O(1).
Lab from_srgb(Color c);
// L*a*b* → sRGB in [0,1] per channel, gamma-encoded, NOT clipped (out-of-gamut colours
// give values outside [0,1]).
void to_srgb_unclipped(const Lab& lab, double rgb[3]);
// True when the colour is displayable in sRGB (every channel within [-eps, 1+eps]).
bool in_gamut(const Lab& lab, double eps = 1e-6);
// L*a*b* → 8-bit sRGB. Out-of-gamut colours keep L* and hue and lose chroma until they
// fit (bisection on chroma), rather than clipping channels, which would shift the hue.
Color to_srgb(const Lab& lab);

// Largest chroma C such that (L, C cos h, C sin h) is in the sRGB gamut, by bisection
// to `tol`. hue in radians. O(log(C_max / tol)).
double max_chroma(double L, double hue, double tol = 1e-3);

// The same CIEDE2000 under the name the colour methods use.
inline double delta_e00(const Lab& x, const Lab& y) { return stipplot::ciede2000(x, y); }

}  // namespace stipplot::lab
