#pragma once
// Lengths as users write them: a decimal number with an optional unit, one grammar for
// every option and for page sizes. Paper units: mm, cm, in, pt (1/72 in), px (1/96 in,
// CSS's and SVG's pixel); a bare number is millimetres. Options that size a mark against
// the photo (Length::parse) read "px" as an input-image pixel instead, which becomes
// millimetres only once the image is placed on the page, and want the unit written.
#include <string>
#include <string_view>

namespace stipplot {

// A decimal of at most 15 digits with an optional sign and point ("-12.345", "+.5",
// "7."), as the correctly rounded double strtod gives, -0 included; false for anything
// else (then strtod or from_chars). Exact: the digits' integer and 10^k are exact
// doubles, so one division rounds once (Clinger's fast path). Millions of numbers are
// read this way (an SVG's coordinates, a G-code job's words). O(length).
bool short_decimal(std::string_view text, double& value);

// Splits "12.5mm", " 3 px", "0.4" into the number and the unit word (lower-cased, maybe
// empty). False unless the text is a plain decimal number (sign, digits, point,
// exponent; no hex, inf or nan) followed by nothing but letters and blanks.
bool split_number_unit(std::string_view text, double& value, std::string& unit);

// Millimetres per paper unit: "" and "mm" 1, "cm" 10, "in" 25.4, "pt" 25.4/72, "px" 25.4/96;
// 0 for anything else.
double mm_per_unit(std::string_view unit);

// A length in millimetres on paper, or in input-image pixels.
struct Length {
  double value = 0;
  bool in_px = false;
  double to_mm(double mm_per_px) const { return in_px ? value * mm_per_px : value; }

  // What a bare number means. One rule: a length has its unit. Where an option takes
  // either a length on paper or one in input pixels, a bare number could be read both
  // ways (the papers give theirs in pixels; stipplot's defaults show "3px"), so it is
  // refused, naming both readings (refuse, the default); 0 needs none. Where the option's
  // bare number has a unit of its own that its default shows (pointillism --radius 3, in
  // grid cells of a pen width, = 3px), px.
  enum class Bare { refuse, px };
  // "0.4mm", "1.5px", "0.1cm", "0.02in", "1pt", "0". Throws UserError naming `option` for
  // a malformed, negative or non-finite length, an unknown unit, or a bare number that
  // `bare` refuses.
  static Length parse(std::string_view text, const char* option, Bare bare = Bare::refuse);
};

// A length that only exists on paper (margins, pen widths, tolerances): bare numbers in
// mm, "px" the CSS pixel of 1/96 in. Returns millimetres.
double parse_paper_mm(std::string_view text, const char* option);

}  // namespace stipplot
