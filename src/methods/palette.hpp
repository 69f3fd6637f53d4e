#pragma once
// A set of real pens the user owns, read from a TOML file, and the nearest of them to a
// colour. One reader for every method that draws with user pens (sketch, pointillism)
// and for the built-in pointillism fineliners. Format:
//
//   name = "Stabilo point 88, 8 colours"   # optional
//   [[pen]]
//   name = "red"            # unique, non-empty
//   color = "#d7261e"       # #rrggbb (or #rgb / an SVG colour name)
//   width = 0.4             # mm, optional (the method's default), 0.01 .. 50
//
// Unknown keys are rejected so a typo ("colour", "widht") is not silently ignored.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "eval/lab.hpp"
#include "geometry/drawing.hpp"

namespace stipplot {

struct Palette {
  std::string name;
  std::vector<Pen> pens;
};

// Parses TOML text; `source` names the file in error messages; pens without a width get
// `default_width_mm`. Throws UserError with one line naming the file, the pen and the
// problem: TOML syntax (with its line), no pens, missing or duplicate names, bad colours,
// bad widths, unknown keys. O(text length + pens log pens).
Palette parse_palette(const std::string& toml_text, const std::string& source = "palette",
                      double default_width_mm = 0.3);

// Folders searched for a palette given by name (--pens fineliner12), in order:
// $STIPPLOT_PENS, a pens/ folder next to the executable, ../share/stipplot/pens beside
// it (an installed stipplot), the source tree's examples/pens.
std::vector<std::filesystem::path> palette_dirs();

// The file --pens means: PATH itself when it is a file, has a '/' or ends in .toml;
// otherwise NAME.toml in the first of palette_dirs() holding it. Throws UserError
// naming the folders searched when there is none.
std::string find_palette(const std::string& name_or_path);

// Reads and parses a palette file, given by path or by name (find_palette); throws
// UserError if it cannot be found or read.
Palette load_palette(const std::string& name_or_path, double default_width_mm = 0.3);

// Nearest pen to a colour by CIEDE2000, memoised per 8-bit colour (photos repeat
// colours a lot). O(pens) per new colour, O(1) for a repeated one.
class PenMatcher {
 public:
  explicit PenMatcher(std::vector<Pen> pens);  // throws UserError when empty
  size_t nearest(Color c);
  const std::vector<Pen>& pens() const { return pens_; }

 private:
  std::vector<Pen> pens_;
  std::vector<Lab> pen_lab_;
  std::unordered_map<uint32_t, uint32_t> cache_;
};

// How far a pen is from the ink a layer asks for. `colour`: CIEDE2000 between them.
// `hue`: for a process ink and a pen that both have a hue (chroma above 10), CIEDE2000
// between the ink and the pen's chroma and hue at the ink's lightness, since a separation
// sets an ink's lightness by its coverage, so a pen of the ink's hue but another
// lightness still separates the image right; a grey pen, or an achromatic ink (black),
// keeps the full difference (without a hue only the colour itself can match).
enum class InkMatch { colour, hue };
double ink_distance(Color ink, Color pen, InkMatch how);

// Every layer drawn with the nearest of `pens` to its pen colour (ink_distance): the layer
// takes that pen's name and colour and keeps its own width (the method sized its marks
// for it); a layer whose colour is nearer the paper than every pen is dropped when
// `paper_is_free`. Layers given one pen are merged (merge_layers_by_pen), light to dark.
// O(primitives + layers x pens).
Drawing map_layers_to_pens(const Drawing& d, const std::vector<Pen>& pens, bool paper_is_free,
                           InkMatch how = InkMatch::colour);

// The `n` of `palette_size` pens that best reproduce an image, by greedy forward
// selection: n rounds, each adding the pen whose addition gives the lowest `error` of the
// chosen set (indices ascending). Exhaustive search would cost C(P, n) evaluations;
// greedy costs n P - n (n - 1) / 2 calls of `error`. Returns the indices, ascending.
std::vector<size_t> choose_pens_greedy(size_t palette_size, size_t n,
                                       const std::function<double(const std::vector<size_t>&)>& error);

// How many evaluations choose_pens_greedy makes for n of p pens.
size_t greedy_pen_evaluations(size_t palette_size, size_t n);

}  // namespace stipplot
