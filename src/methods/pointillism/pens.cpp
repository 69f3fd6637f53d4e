#include "methods/pointillism/pens.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "util/error.hpp"

namespace stipplot::pointillism {

std::vector<Pen> default_pens() {
  // Approximate ink colours of a 20-pen fineliner set (0.4 mm tips).
  const std::pair<const char*, const char*> inks[] = {
      {"black", "#1e1e1e"},       {"grey", "#8a8a8a"},        {"light grey", "#bdbdbd"},
      {"red", "#e42a26"},         {"carmine", "#b0243a"},     {"pink", "#f06fa8"},
      {"lilac", "#b48ad6"},       {"violet", "#6a3d9a"},      {"dark blue", "#1f3a93"},
      {"blue", "#2a62c9"},        {"azure", "#3fa9f5"},       {"light blue", "#8ecdf0"},
      {"turquoise", "#00a6a6"},   {"dark green", "#1e7b45"},  {"green", "#3aa655"},
      {"light green", "#9ed36a"}, {"yellow", "#ffe23b"},      {"orange", "#ff8a1f"},
      {"brown", "#8b5a2b"},       {"ochre", "#c28b45"},
  };
  std::vector<Pen> pens;
  for (const auto& [name, hex] : inks) pens.push_back(Pen{name, Color::parse(hex), 0.4});
  return pens;
}

std::vector<Pen> parse_pens(const std::string& text, const std::string& source) {
  toml::table doc;
  try {
    doc = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << source << ":" << e.source().begin.line << ": " << e.description();
    throw UserError(os.str());
  }
  for (const auto& [key, node] : doc) {
    if (key.str() != "pen")
      throw UserError(source + ": unknown key '" + std::string(key.str()) + "' (expected [[pen]] tables)");
  }
  const toml::array* list = doc["pen"].as_array();
  if (!list || list->empty()) throw UserError(source + ": no pens (expected [[pen]] tables with name, color, width)");
  std::vector<Pen> pens;
  for (const auto& node : *list) {
    const toml::table* t = node.as_table();
    const std::string where = source + ":" + std::to_string(node.source().begin.line);
    if (!t) throw UserError(where + ": each pen must be a [[pen]] table");
    for (const auto& [key, v] : *t) {
      if (key.str() != "name" && key.str() != "color" && key.str() != "width")
        throw UserError(where + ": unknown pen field '" + std::string(key.str()) + "' (name, color, width)");
    }
    Pen p;
    auto name = (*t)["name"].value<std::string>();
    if (!name || name->empty()) throw UserError(where + ": pen needs a non-empty name = \"...\"");
    p.name = *name;
    auto color = (*t)["color"].value<std::string>();
    if (!color) throw UserError(where + ": pen '" + p.name + "' needs color = \"#rrggbb\"");
    if (!Color::try_parse(*color, p.color))
      throw UserError(where + ": pen '" + p.name + "': bad color '" + *color + "' (expected #rrggbb)");
    p.width_mm = 0.4;
    if (t->contains("width")) {
      auto w = (*t)["width"].value<double>();
      if (!w || !std::isfinite(*w) || *w <= 0 || *w > 50)
        throw UserError(where + ": pen '" + p.name + "': width must be a number of mm in (0, 50]");
      p.width_mm = *w;
    }
    pens.push_back(p);
  }
  return pens;
}

std::vector<Pen> load_pens(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError("--pens " + path + ": cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_pens(ss.str(), path);
}

PenMatcher::PenMatcher(std::vector<Pen> pens) : pens_(std::move(pens)) {
  if (pens_.empty()) throw UserError("--pens: the palette is empty");
  for (const auto& p : pens_) pen_lab_.push_back(lab::from_srgb(p.color));
}

size_t PenMatcher::nearest(Color c) {
  const uint32_t key = (uint32_t{c.r} << 16) | (uint32_t{c.g} << 8) | c.b;
  if (auto it = cache_.find(key); it != cache_.end()) return it->second;
  const lab::Lab x = lab::from_srgb(c);
  size_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < pen_lab_.size(); ++i) {
    const double d = lab::delta_e00(x, pen_lab_[i]);
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  cache_.emplace(key, static_cast<uint32_t>(best));
  return best;
}

}  // namespace stipplot::pointillism
