#include "util/units.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>

#include "util/error.hpp"

namespace stipplot {

namespace {
bool blank(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }
bool digit(char c) { return c >= '0' && c <= '9'; }

// Length of the decimal number at the start of s: [-+]digits[.digits][e[-+]digits],
// at least one digit before or after the point; 0 if there is none.
size_t number_length(std::string_view s) {
  size_t i = 0, digits = 0;
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
  while (i < s.size() && digit(s[i])) ++i, ++digits;
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && digit(s[i])) ++i, ++digits;
  }
  if (digits == 0) return 0;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    size_t j = i + 1;
    if (j < s.size() && (s[j] == '-' || s[j] == '+')) ++j;
    if (j < s.size() && digit(s[j])) {
      while (j < s.size() && digit(s[j])) ++j;
      i = j;
    }
  }
  return i;
}
}  // namespace

bool short_decimal(std::string_view text, double& value) {
  static constexpr double kPow10[] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
  if (text.empty()) return false;
  size_t i = 0;
  const bool negative = text[0] == '-';
  if (text[0] == '-' || text[0] == '+') ++i;
  uint64_t m = 0;
  int count = 0, fraction = -1;  // digits read; digits after the point (-1: no point yet)
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c >= '0' && c <= '9') {
      if (++count > 15) return false;
      m = m * 10 + static_cast<uint64_t>(c - '0');
      if (fraction >= 0) ++fraction;
    } else if (c == '.' && fraction < 0) {
      fraction = 0;
    } else {
      return false;
    }
  }
  if (count == 0) return false;
  const double v = static_cast<double>(m) / kPow10[std::max(fraction, 0)];
  value = negative ? -v : v;
  return true;
}

bool split_number_unit(std::string_view text, double& value, std::string& unit) {
  while (!text.empty() && blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && blank(text.back())) text.remove_suffix(1);
  const size_t n = number_length(text);
  if (n == 0) return false;
  std::string_view num = text.substr(0, n);
  const bool negative = num.front() == '-';
  if (num.front() == '-' || num.front() == '+') num.remove_prefix(1);
  double v = 0;
  if (!short_decimal(num, v)) {
    const auto [end, ec] = std::from_chars(num.data(), num.data() + num.size(), v);
    if (ec != std::errc() || end != num.data() + num.size()) return false;
  }
  std::string_view rest = text.substr(n);
  while (!rest.empty() && blank(rest.front())) rest.remove_prefix(1);
  unit.clear();
  for (char c : rest) {
    if (!std::isalpha(static_cast<unsigned char>(c))) return false;
    unit += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  value = negative ? -v : v;
  return true;
}

double mm_per_unit(std::string_view unit) {
  if (unit.empty() || unit == "mm") return 1;
  if (unit == "cm") return 10;
  if (unit == "in") return 25.4;
  if (unit == "pt") return 25.4 / 72;
  if (unit == "px") return 25.4 / 96;
  return 0;
}

namespace {
[[noreturn]] void bad_length(std::string_view text, const char* option, const char* examples) {
  throw UserError(std::string(option) + ": expected a length >= 0 such as " + examples + ", got '" +
                  std::string(text) + "'");
}
// No length on paper is longer than a km, so none can overflow what it sizes.
void require_at_most_a_km(double mm, std::string_view text, const char* option) {
  if (!(mm <= 1e6))
    throw UserError(std::string(option) + ": " + std::string(text) + " is longer than 1000000 mm (1 km)");
}
}  // namespace

Length Length::parse(std::string_view text, const char* option, Bare bare) {
  const char* examples = bare == Bare::px ? "3, 3px or 0.5mm (a bare number is input pixels)"
                                          : "0.4mm or 1.5px (mm, cm, in, pt or px of the input image)";
  double v = 0;
  std::string unit;
  if (!split_number_unit(text, v, unit) || !std::isfinite(v) || v < 0) bad_length(text, option, examples);
  if (unit.empty() && bare == Bare::refuse && v != 0) {
    std::string n(text);
    while (!n.empty() && blank(n.front())) n.erase(n.begin());
    while (!n.empty() && blank(n.back())) n.pop_back();
    throw UserError(std::string(option) + " " + n + ": a length needs a unit here: " + n + "px (input pixels) or " + n +
                    "mm (on paper)");
  }
  Length l;
  if (unit == "px" || (unit.empty() && bare == Bare::px)) {
    if (!(v <= 1e6)) throw UserError(std::string(option) + ": " + std::string(text) + " is more than 1000000 px");
    l.in_px = true;
    l.value = v;
    return l;
  }
  const double f = mm_per_unit(unit);
  if (f == 0) bad_length(text, option, examples);
  l.value = v * f;
  require_at_most_a_km(l.value, text, option);
  return l;
}

double parse_paper_mm(std::string_view text, const char* option) {
  double v = 0;
  std::string unit;
  const char* examples = "10, 10mm, 1cm, 0.5in, 12pt or 40px";
  if (!split_number_unit(text, v, unit) || !std::isfinite(v) || v < 0) bad_length(text, option, examples);
  const double f = mm_per_unit(unit);
  if (f == 0) bad_length(text, option, examples);
  require_at_most_a_km(v * f, text, option);
  return v * f;
}

}  // namespace stipplot
