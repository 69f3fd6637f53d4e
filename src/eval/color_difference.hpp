#pragma once
// Colour fidelity as the mean CIEDE2000 between the blurred drawing and the blurred
// input (blurring first compares tones and colours, not individual strokes). Shared by
// the colour methods (sketch, pointillism).
#include "eval/lab.hpp"
#include "image/image.hpp"

namespace stipplot {

// Mean CIEDE2000 over the input's pixels after both images are Gaussian-blurred with
// `sigma_px` (input pixels); `drawn` covers exactly the input's extent at any resolution
// (both are area-resampled to the smaller of the two sizes first, the blur scaled with
// them). sRGB -> Lab (D65) by OpenCV.
// O(pixels of both images).
double mean_delta_e00_blurred(const Image& input, const Image& drawn, double sigma_px);

}  // namespace stipplot
