#pragma once
// --max-pens for the colour methods that draw with a palette (--pens): the N pens of the
// palette that best reproduce the image, chosen on a small copy of the drawing so the
// search costs about one run of the method.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "cli/method_command.hpp"
#include "geometry/drawing.hpp"
#include "image/image.hpp"
#include "methods/placement.hpp"

namespace stipplot::cli {

// Adds --max-pens N (0: every pen of the palette) to a method that takes --pens.
void add_max_pens_option(CLI::App* cmd, int& max_pens);  // -1: not given

// One line naming the problem when --max-pens is given without a palette, or is outside
// 1 .. the palette's size.
void check_max_pens(int max_pens, size_t palette_size, const std::string& palette_name);

// A method's input shrunk for the search: the image resampled and the page and margin
// scaled by one factor, so marks keep their size in millimetres (and so the tones they
// lay) while there are about 1/evaluations as many. O(input pixels).
struct SearchInput {
  Image image;
  Placement placement;
};
SearchInput reduced_input(const MethodInput& in, size_t evaluations);

struct PenChoice {
  std::vector<Pen> pens;   // in palette order
  double mean_de00 = 0;    // of the chosen set on the search input
  size_t evaluations = 0;  // drawings rendered and measured
  double seconds = 0;
};

// The `n` pens of `palette` whose drawing, `drawing_for(pens)` on the search input,
// reproduces `search.image` best: greedy forward selection (methods/palette.hpp) by the
// mean CIEDE2000 of the blurred (sigma 1.5 mm) pen-true render against the blurred image
// (drawn without planning when the marks are all discs or all lines and touches; else of a
// plan with a greedy tour, no improvement, fills hatched). n P - n (n - 1) / 2 drawings,
// plans and renders of the search input, P the palette's size, each O(marks log marks +
// render pixels x pens); reduced_input sizes the copy so they add up to about one run.
PenChoice choose_pens(const std::vector<Pen>& palette, size_t n, const SearchInput& search,
                      const std::function<Drawing(const std::vector<Pen>&)>& drawing_for);

// The chosen pens in the method's --json ("max_pens": names, error, cost) and sentence.
void report_pen_choice(const PenChoice& choice, MethodResult& r);

}  // namespace stipplot::cli
