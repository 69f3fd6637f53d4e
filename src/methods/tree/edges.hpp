#pragma once
// Major edges (seed 002, §6): mean-shift filtering flattens texture (the idea behind
// EDISON, which the paper used), Canny finds the edges of what is left, and chains
// shorter than a length are dropped so only major edges remain.
#include <cstdint>
#include <vector>

#include "image/image.hpp"

namespace stipplot::tree {

struct EdgeParams {
  double spatial_radius = 10;  // mean-shift spatial window (px of the input)
  double color_radius = 30;    // mean-shift colour window (RGB units)
  double scale = 0.5;          // mean shift runs on the image scaled by this (its cost grows as r²·n)
  double canny_low = 50, canny_high = 150;
  int min_length = 60;         // px; edge chains (8-connected) with fewer pixels are dropped
  void validate() const;      // UserError naming the option
};

// 255 on major-edge pixels, 0 elsewhere; row-major, image size.
// O(n · r_s² · iterations) for the mean shift plus O(n) for Canny and the components.
std::vector<uint8_t> major_edges(const Image& image, const EdgeParams& p);

// Euclidean distance (px) of every pixel to the nearest set pixel of `mask`
// (all pixels get the image diagonal if the mask is empty). O(n).
std::vector<float> distance_from(const std::vector<uint8_t>& mask, int width, int height);

}  // namespace stipplot::tree
