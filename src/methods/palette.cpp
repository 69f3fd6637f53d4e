#include "methods/palette.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "util/error.hpp"
#include "util/executable.hpp"

namespace stipplot {

namespace {
[[noreturn]] void fail(const std::string& source, const std::string& what) { throw UserError(source + ": " + what); }

// One [[pen]] table; `where` names it ("pen 3", then "pen 3 'red'" once its name is known).
Pen parse_pen(const toml::node& node, size_t index, const std::string& source, double default_width_mm) {
  std::string where = "pen " + std::to_string(index);
  const toml::table* t = node.as_table();
  if (!t) fail(source, where + " is not a table: write each pen as [[pen]]");
  Pen pen;
  pen.width_mm = default_width_mm;
  if (const toml::node* name = t->get("name")) {
    auto s = name->value<std::string>();
    if (!s || s->empty()) fail(source, where + ": 'name' must be a non-empty string");
    pen.name = *s;
  } else {
    fail(source, where + ": missing 'name'");
  }
  where += " '" + pen.name + "'";
  bool has_color = false;
  for (auto&& [key, v] : *t) {
    const std::string k(key.str());
    if (k == "name") continue;
    if (k == "color") {
      auto s = v.value<std::string>();
      if (!s) fail(source, where + ": 'color' must be a string such as \"#d7261e\"");
      if (!Color::try_parse(*s, pen.color)) fail(source, where + ": bad color '" + *s + "' (use #rrggbb, e.g. \"#d7261e\")");
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
  if (!has_color) fail(source, where + ": missing 'color'");
  return pen;
}
}  // namespace

Palette parse_palette(const std::string& text, const std::string& source, double default_width_mm) {
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
  for (const toml::node& pn : *pens) {
    Pen pen = parse_pen(pn, pal.pens.size() + 1, source, default_width_mm);
    if (!seen.insert(pen.name).second)
      fail(source, "pen " + std::to_string(pal.pens.size() + 1) + ": duplicate pen name '" + pen.name + "'");
    pal.pens.push_back(pen);
  }
  return pal;
}

std::vector<std::filesystem::path> palette_dirs() {
  std::vector<std::filesystem::path> dirs;
  if (const char* env = std::getenv("STIPPLOT_PENS"); env && *env) dirs.emplace_back(env);
  if (const std::filesystem::path exe = executable_dir(); !exe.empty()) {
    dirs.push_back(exe / "pens");
    dirs.push_back(exe.parent_path() / "share" / "stipplot" / "pens");
  }
#ifdef STIPPLOT_PENS_DIR
  dirs.emplace_back(STIPPLOT_PENS_DIR);
#endif
  return dirs;
}

std::string find_palette(const std::string& name_or_path) {
  namespace fs = std::filesystem;
  const std::string& s = name_or_path;
  std::error_code ec;
  const bool is_path = s.find('/') != std::string::npos || (s.size() > 5 && s.compare(s.size() - 5, 5, ".toml") == 0) ||
                       fs::is_regular_file(s, ec);
  if (is_path || s.empty()) return s;
  std::string searched;
  for (const fs::path& dir : palette_dirs()) {
    const fs::path f = dir / (s + ".toml");
    if (fs::is_regular_file(f, ec)) return f.string();
    searched += (searched.empty() ? "" : ", ") + dir.string();
  }
  throw UserError("--pens " + s + ": no such file, nor a palette of that name (" + s + ".toml) in " + searched);
}

Palette load_palette(const std::string& name_or_path, double default_width_mm) {
  const std::string path = find_palette(name_or_path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError("--pens " + path + ": cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw UserError("--pens " + path + ": cannot read the file");
  return parse_palette(ss.str(), path, default_width_mm);
}

PenMatcher::PenMatcher(std::vector<Pen> pens) : pens_(std::move(pens)) {
  if (pens_.empty()) throw UserError("--pens: the palette is empty");
  for (const auto& p : pens_) pen_lab_.push_back(lab::from_srgb(p.color));
}

size_t PenMatcher::nearest(Color c) {
  const uint32_t key = (uint32_t{c.r} << 16) | (uint32_t{c.g} << 8) | c.b;
  if (auto it = cache_.find(key); it != cache_.end()) return it->second;
  const Lab x = lab::from_srgb(c);
  size_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < pen_lab_.size(); ++i) {
    const double d = ciede2000(x, pen_lab_[i]);
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  cache_.emplace(key, static_cast<uint32_t>(best));
  return best;
}

double ink_distance(Color ink, Color pen, InkMatch how) {
  const Lab a = lab::from_srgb(ink), b = lab::from_srgb(pen);
  constexpr double achromatic = 10;  // chroma below which a colour has no hue to speak of
  if (how == InkMatch::colour || std::hypot(a.a, a.b) <= achromatic || std::hypot(b.a, b.b) <= achromatic)
    return ciede2000(a, b);
  return ciede2000(a, Lab{a.L, b.a, b.b});
}

Drawing map_layers_to_pens(const Drawing& d, const std::vector<Pen>& pens, bool paper_is_free, InkMatch how) {
  std::vector<Pen> candidates = pens;
  if (paper_is_free) candidates.push_back(Pen{"paper", d.page.paper, 0});
  if (candidates.empty()) throw UserError("--pens: the palette is empty");
  Drawing out;
  out.page = d.page;
  for (const Layer& l : d.layers) {
    size_t k = 0;
    for (size_t i = 1; i < candidates.size(); ++i)
      if (ink_distance(l.pen.color, candidates[i].color, how) < ink_distance(l.pen.color, candidates[k].color, how))
        k = i;
    if (k == pens.size()) continue;  // the paper
    Layer m = l;
    m.pen.name = pens[k].name;
    m.pen.color = pens[k].color;
    for (Circle& c : m.circles)
      if (c.filled) c.fill = pens[k].color;
    for (Area& a : m.areas) a.fill = pens[k].color;
    out.layers.push_back(std::move(m));
  }
  merge_layers_by_pen(out);
  return out;
}

std::vector<size_t> choose_pens_greedy(size_t palette_size, size_t n,
                                       const std::function<double(const std::vector<size_t>&)>& error) {
  std::vector<size_t> chosen;
  std::vector<bool> taken(palette_size, false);
  for (size_t round = 0; round < std::min(n, palette_size); ++round) {
    size_t best = palette_size;
    double best_error = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < palette_size; ++i) {
      if (taken[i]) continue;
      std::vector<size_t> trial = chosen;
      trial.insert(std::upper_bound(trial.begin(), trial.end(), i), i);
      const double e = error(trial);
      if (e < best_error || best == palette_size) best_error = e, best = i;
    }
    taken[best] = true;
    chosen.insert(std::upper_bound(chosen.begin(), chosen.end(), best), best);
  }
  return chosen;
}

size_t greedy_pen_evaluations(size_t palette_size, size_t n) {
  n = std::min(n, palette_size);
  return n * palette_size - n * (n - 1) / 2;
}

}  // namespace stipplot
