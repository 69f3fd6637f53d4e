#pragma once
// Numbers as the writers print them: at most `decimals` digits after the point, trailing
// zeros and a lone point trimmed, "-0" as "0". std::to_chars prints as printf's "%.*f"
// does (the same digits, correctly rounded) without printf's format parsing and its
// multi-precision arithmetic: a tenth of the time, which an SVG of a million points feels.
#include <charconv>
#include <string>
#include <string_view>

namespace stipplot {

// Appends v to out. O(digits). v must be finite (the callers check).
inline void append_decimal(std::string& out, double v, int decimals) {
  char small[64];
  std::string large;
  char* buf = small;
  char* end = small + sizeof small;
  auto r = std::to_chars(buf, end, v, std::chars_format::fixed, decimals);
  if (r.ec != std::errc()) {  // a huge value: up to 309 digits before the point
    large.resize(400 + static_cast<size_t>(decimals));
    buf = large.data();
    end = buf + large.size();
    r = std::to_chars(buf, end, v, std::chars_format::fixed, decimals);
  }
  std::string_view s(buf, static_cast<size_t>(r.ptr - buf));
  if (s.find('.') != std::string_view::npos) {
    while (s.back() == '0') s.remove_suffix(1);
    if (s.back() == '.') s.remove_suffix(1);
  }
  if (s == "-0") s = "0";
  out += s;
}

}  // namespace stipplot
