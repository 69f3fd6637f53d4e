#pragma once
// A Gaussian blur whose cost does not grow with sigma: OpenCV's kernel is about 6 sigma
// wide, so sigma = 10^6 on a 1 x 10^6 image is 10^12 operations. Past kDirectSigma the
// image is shrunk (area average) until the blur is kDirectSigma px, blurred, and enlarged
// back; at such widths the result is smooth, so the detour changes it by well under a
// grey level. O(pixels x min(sigma, kDirectSigma)).
#include <opencv2/core.hpp>

namespace stipplot {

inline constexpr double kDirectSigma = 32;
void gaussian_blur_bounded(const cv::Mat& in, cv::Mat& out, double sigma, int border);

// OpenCV's Gaussian blur (sigma_y = sigma_x), in bands of 128 rows on every thread. A band
// is a view into the whole image, so OpenCV reads the rows beyond it from the image itself
// (the border applies at the image's edges only): each pixel is the sum it is without
// bands, bit for bit (test "[blur]"). In place when `out` is `in`. O(pixels x sigma).
void gaussian_blur_rows(const cv::Mat& in, cv::Mat& out, double sigma, int border);

}  // namespace stipplot
