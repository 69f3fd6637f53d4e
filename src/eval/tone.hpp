#pragma once
// Tone on paper: how the blurred drawing's grey levels follow the blurred input's. Both
// are Gaussian-blurred at the mark spacing (what the eye averages at a viewing distance),
// then the drawing's grey is fitted against the input's by least squares. A drawing with
// the photo's tones has slope 1 and a high Pearson r; a faded one a slope below 1.
#include "image/image.hpp"

namespace stipplot {

struct ToneFit {
  double slope = 0, intercept = 0;  // drawn = slope * input + intercept, grey in [0, 1]
  double pearson = 0;               // correlation of the two blurred greys
  double mean_input = 0, mean_drawn = 0;  // mean grey (1 = white)
};

// Grey = Rec. 601 luma of the sRGB codes / 255 (the methods' d / 255). `drawn` covers
// exactly the input's extent at any resolution (both are compared at the smaller size,
// the blur scaled with it). O(pixels of both images).
ToneFit fit_tone(const Image& input, const Image& drawn, double sigma_px);

}  // namespace stipplot
