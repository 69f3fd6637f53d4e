#include "geometry/color.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>

#include "util/error.hpp"

namespace stipplot {

std::string Color::hex() const {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", r, g, b);
  return buf;
}

bool Color::try_parse(const std::string& text_in, Color& out) {
  std::string t = text_in;
  std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return std::tolower(c); });
  while (!t.empty() && std::isspace(static_cast<unsigned char>(t.back()))) t.pop_back();
  while (!t.empty() && std::isspace(static_cast<unsigned char>(t.front()))) t.erase(t.begin());
  auto hexval = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
  };
  if (!t.empty() && t[0] == '#') {
    if (t.size() == 4 || t.size() == 7) {
      int v[6];
      size_t n = t.size() - 1;
      for (size_t i = 0; i < n; ++i)
        if ((v[i] = hexval(t[i + 1])) < 0) return false;
      if (n == 3) {
        out = {static_cast<uint8_t>(v[0] * 17), static_cast<uint8_t>(v[1] * 17), static_cast<uint8_t>(v[2] * 17)};
      } else {
        out = {static_cast<uint8_t>(v[0] * 16 + v[1]), static_cast<uint8_t>(v[2] * 16 + v[3]),
               static_cast<uint8_t>(v[4] * 16 + v[5])};
      }
      return true;
    }
    return false;
  }
  int r, g, b, used = 0;
  if (std::sscanf(t.c_str(), "rgb( %d , %d , %d )%n", &r, &g, &b, &used) == 3 && used == static_cast<int>(t.size())) {
    if (r < 0 || r > 255 || g < 0 || g > 255 || b < 0 || b > 255) return false;
    out = {static_cast<uint8_t>(r), static_cast<uint8_t>(g), static_cast<uint8_t>(b)};
    return true;
  }
  static const std::map<std::string, Color> names = {
      {"black", {0, 0, 0}},         {"white", {255, 255, 255}},   {"red", {255, 0, 0}},
      {"lime", {0, 255, 0}},        {"green", {0, 128, 0}},       {"blue", {0, 0, 255}},
      {"yellow", {255, 255, 0}},    {"cyan", {0, 255, 255}},      {"aqua", {0, 255, 255}},
      {"magenta", {255, 0, 255}},   {"fuchsia", {255, 0, 255}},   {"grey", {128, 128, 128}},
      {"gray", {128, 128, 128}},    {"silver", {192, 192, 192}},  {"maroon", {128, 0, 0}},
      {"navy", {0, 0, 128}},        {"olive", {128, 128, 0}},     {"purple", {128, 0, 128}},
      {"teal", {0, 128, 128}},      {"orange", {255, 165, 0}},    {"brown", {165, 42, 42}},
      {"pink", {255, 192, 203}},    {"darkgreen", {0, 100, 0}},   {"darkblue", {0, 0, 139}},
      {"darkred", {139, 0, 0}},     {"lightgrey", {211, 211, 211}}, {"lightgray", {211, 211, 211}},
      {"darkgrey", {169, 169, 169}}, {"darkgray", {169, 169, 169}}, {"violet", {238, 130, 238}},
      {"gold", {255, 215, 0}},      {"indigo", {75, 0, 130}},     {"turquoise", {64, 224, 208}},
      {"skyblue", {135, 206, 235}}, {"crimson", {220, 20, 60}},   {"tomato", {255, 99, 71}}};
  auto it = names.find(t);
  if (it == names.end()) return false;
  out = it->second;
  return true;
}

Color Color::parse(const std::string& text) {
  Color c;
  if (!try_parse(text, c)) throw UserError("not a colour: '" + text + "' (use #rrggbb, #rgb, rgb(r,g,b) or a colour name)");
  return c;
}

}  // namespace stipplot
