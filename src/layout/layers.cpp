#include "layout/layers.hpp"

#include <cctype>
#include <vector>

#include "util/error.hpp"

namespace stipplot::layout {

namespace {

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t comma = text.find(',', pos);
    if (comma == std::string::npos) comma = text.size();
    items.push_back(trim(text.substr(pos, comma - pos)));
    pos = comma + 1;
  }
  return items;
}

bool whole_number(const std::string& s, int& out) {
  if (s.empty() || s.size() > 6) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  out = std::stoi(s);
  return true;
}

std::string layer_list(const Drawing& d) {
  std::string s;
  for (size_t i = 0; i < d.layers.size(); ++i)
    s += (i ? ", " : "") + std::to_string(i + 1) + " " + d.layers[i].pen.name + " " + d.layers[i].pen.color.hex();
  return s.empty() ? "none" : s;
}

// The layers an item names: a position, else every layer of that name, else of that
// pen colour (colours: only when `by_colour`).
std::vector<size_t> matching_layers(const Drawing& d, const std::string& item, bool by_colour) {
  std::vector<size_t> out;
  int n;
  if (whole_number(item, n)) {
    if (n >= 1 && static_cast<size_t>(n) <= d.layers.size()) out.push_back(static_cast<size_t>(n - 1));
    return out;
  }
  for (size_t i = 0; i < d.layers.size(); ++i)
    if (d.layers[i].pen.name == item) out.push_back(i);
  Color c;
  if (out.empty() && by_colour && Color::try_parse(item, c))
    for (size_t i = 0; i < d.layers.size(); ++i)
      if (d.layers[i].pen.color == c) out.push_back(i);
  return out;
}

}  // namespace

void keep_layers(Drawing& d, const std::string& selection) {
  resolve_pen_numbers(d);
  std::vector<bool> keep(d.layers.size(), false);
  for (const std::string& item : split_list(selection)) {
    if (item.empty()) throw UserError("--layer: expected layer numbers or names separated by commas, got '" + selection + "'");
    const auto hit = matching_layers(d, item, false);
    if (hit.empty()) throw UserError("--layer " + item + ": no such layer (the drawing has: " + layer_list(d) + ")");
    for (size_t i : hit) keep[i] = true;
  }
  std::vector<Layer> kept;
  for (size_t i = 0; i < d.layers.size(); ++i)
    if (keep[i]) kept.push_back(std::move(d.layers[i]));
  d.layers = std::move(kept);
}

void apply_pen_map(Drawing& d, const std::string& map) {
  std::vector<int> pen(d.layers.size(), 0);
  for (const std::string& item : split_list(map)) {
    const size_t eq = item.rfind('=');
    int number = 0;
    if (eq == std::string::npos || !whole_number(trim(item.substr(eq + 1)), number) || number < 1 || number > 9999)
      throw UserError("--pen-map: expected LAYER=PEN items such as red=2,#0000ff=3,1=1 (pens 1 to 9999), got '" + item + "'");
    const std::string key = trim(item.substr(0, eq));
    const auto hit = matching_layers(d, key, true);
    if (hit.empty())
      throw UserError("--pen-map " + item + ": '" + key + "' names no layer, layer name or pen colour (the drawing has: " +
                      layer_list(d) + ")");
    for (size_t i : hit) pen[i] = number;
  }
  for (size_t i = 0; i < d.layers.size(); ++i) d.layers[i].pen.number = pen[i];
  resolve_pen_numbers(d);
}

}  // namespace stipplot::layout
