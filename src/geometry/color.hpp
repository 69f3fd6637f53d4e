#pragma once
#include <cstdint>
#include <string>

namespace stipplot {

// An sRGB colour, 8 bits a channel.
struct Color {
  uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Color&, const Color&) = default;
  std::string hex() const;  // "#rrggbb"
  // "#rgb", "#rrggbb", or a CSS/SVG colour name; throws UserError otherwise.
  static Color parse(const std::string& text);
  // Like parse but returns false instead of throwing.
  static bool try_parse(const std::string& text, Color& out);
};

namespace colors {
inline constexpr Color black{0, 0, 0};
inline constexpr Color white{255, 255, 255};
inline constexpr Color grey{128, 128, 128};
}  // namespace colors

}  // namespace stipplot
