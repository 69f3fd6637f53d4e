#include "methods/palette.hpp"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "util/error.hpp"

namespace stipplot {

namespace {
[[noreturn]] void fail(const std::string& source, const std::string& what) { throw UserError(source + ": " + what); }
}  // namespace

Palette parse_palette(const std::string& text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << "line " << e.source().begin.line << ": " << e.description();
    fail(source, os.str());
  }
  Palette pal;
  for (auto&& [key, node] : root) {
    if (key == "name") {
      auto s = node.value<std::string>();
      if (!s) fail(source, "'name' must be a string");
      pal.name = *s;
    } else if (key != "pen") {
      fail(source, "unknown key '" + std::string(key.str()) + "' (expected name and [[pen]] tables)");
    }
  }
  const toml::node* pens_node = root.get("pen");
  if (!pens_node) fail(source, "no pens: add at least one [[pen]] table with name and color");
  const toml::array* pens = pens_node->as_array();
  if (!pens) fail(source, "'pen' must be an array of tables: write each pen as [[pen]]");
  if (pens->empty()) fail(source, "no pens: add at least one [[pen]] table with name and color");
  std::set<std::string> seen;
  size_t index = 0;
  for (const toml::node& pn : *pens) {
    ++index;
    const std::string where = "pen " + std::to_string(index);
    const toml::table* t = pn.as_table();
    if (!t) fail(source, where + " is not a table: write each pen as [[pen]]");
    Pen pen;
    pen.width_mm = 0.3;
    bool has_name = false, has_color = false;
    for (auto&& [key, v] : *t) {
      const std::string k(key.str());
      if (k == "name") {
        auto s = v.value<std::string>();
        if (!s || s->empty()) fail(source, where + ": 'name' must be a non-empty string");
        pen.name = *s;
        has_name = true;
      } else if (k == "color" || k == "colour") {
        auto s = v.value<std::string>();
        if (!s) fail(source, where + ": 'color' must be a string such as \"#d7261e\"");
        if (!Color::try_parse(*s, pen.color))
          fail(source, where + ": bad color '" + *s + "' (use #rrggbb, e.g. \"#d7261e\")");
        has_color = true;
      } else if (k == "width") {
        auto w = v.value<double>();
        if (!w || !std::isfinite(*w) || *w < 0.01 || *w > 50)
          fail(source, where + ": 'width' must be a number of millimetres in [0.01, 50]");
        pen.width_mm = *w;
      } else {
        fail(source, where + ": unknown key '" + k + "' (expected name, color, width)");
      }
    }
    if (!has_name) fail(source, where + ": missing 'name'");
    if (!has_color) fail(source, where + " '" + pen.name + "': missing 'color'");
    if (!seen.insert(pen.name).second) fail(source, where + ": duplicate pen name '" + pen.name + "'");
    pal.pens.push_back(pen);
  }
  return pal;
}

Palette load_palette(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError("--pens " + path + ": cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw UserError("--pens " + path + ": cannot read the file");
  return parse_palette(ss.str(), path);
}

}  // namespace stipplot
