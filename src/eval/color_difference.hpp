#pragma once
// Colour difference: CIEDE2000, and colour fidelity as the mean CIEDE2000 between the
// blurred drawing and the blurred input (blurring first compares tones and colours, not
// individual strokes). Shared by the colour methods (sketch, pointillism).
#include "image/image.hpp"

namespace stipplot {

struct Lab {
  double L = 0, a = 0, b = 0;
};

// CIEDE2000 (CIE 142-2001) with kL = kC = kH = 1, following Sharma, Wu & Dalal (2005),
// including their notes on hue wrap-around and zero chroma.
double ciede2000(const Lab& x, const Lab& y);

// Mean CIEDE2000 over the input's pixels after both images are Gaussian-blurred with
// `sigma_px` (input pixels); `drawn` covers exactly the input's extent at any resolution
// (both are area-resampled to the smaller of the two sizes first, the blur scaled with
// them). sRGB -> Lab (D65) by OpenCV.
// O(pixels of both images).
double mean_delta_e00_blurred(const Image& input, const Image& drawn, double sigma_px);

}  // namespace stipplot
