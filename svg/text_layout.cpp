#include "svg/text_layout.hpp"

// hersheyfont.h is a C header without extern "C" of its own.
extern "C" {
#include <hersheyfont.h>
}

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include "util/error.hpp"

namespace stipplot::svgtext {

namespace {

constexpr double kUnitsPerEm = 32;            // Hershey units in one font size
const double kItalicSlant = std::tan(15.0 * 3.14159265358979323846 / 180);

// Fonts are loaded once per process, on the first text that needs them.
class FontCache {
 public:
  const hershey_font* get(const std::string& name) {
    std::lock_guard<std::mutex> lock(m_);
    auto it = fonts_.find(name);
    if (it != fonts_.end()) return it->second.get();
    hershey_font* f = hershey_font_load(name.c_str());
    if (!f)
      throw UserError("text: cannot load the Hershey font '" + name +
                      "' from /usr/share/hershey-fonts (install Debian's hershey-fonts-data package)");
    return fonts_.emplace(name, Owned(f, &hershey_font_free)).first->second.get();
  }

 private:
  using Owned = std::unique_ptr<hershey_font, void (*)(hershey_font*)>;
  std::mutex m_;
  std::map<std::string, Owned> fonts_;
};

FontCache& cache() {
  static FontCache c;
  return c;
}

std::string font_name(const TextStyle& st) {
  std::string f = st.family;
  for (char& c : f) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (f.find("script") != std::string::npos || f.find("cursive") != std::string::npos) return "scripts";
  return st.bold ? "futuram" : "futural";
}

// The glyph of c, or null when the font has none (it holds ASCII 32..126).
const hershey_glyph* glyph_of(const TextStyle& st, char32_t c) {
  if (c < 32 || c > 126) return nullptr;
  hershey_glyph* g = hershey_font_glyph(const_cast<hershey_font*>(cache().get(font_name(st))), static_cast<unsigned char>(c));
  return g && g->width > 0 ? g : nullptr;
}

// A missing glyph takes a space's room, so the words around it keep their places.
double advance(const TextChar& tc) {
  const hershey_glyph* g = glyph_of(tc.style, tc.code);
  if (!g) g = glyph_of(tc.style, ' ');
  return g ? g->width * tc.style.size / kUnitsPerEm : tc.style.size / 2;
}

// The glyph's strokes through `place`, which maps (u along the baseline from the glyph's
// left edge, v down from it) in user units to user space.
template <class Place>
void draw_glyph(const TextChar& tc, Place place, TextResult& out) {
  if (tc.code == ' ' || tc.code == '\t') return;
  const hershey_glyph* g = glyph_of(tc.style, tc.code);
  if (!g) {
    ++out.missing;
    return;
  }
  const double s = tc.style.size / kUnitsPerEm;
  Glyph gl;
  gl.paint = tc.paint;
  for (const hershey_path* p = g->paths; p; p = p->next) {
    std::vector<Vec2> stroke;
    stroke.reserve(p->nverts);
    for (unsigned k = 0; k < p->nverts; ++k) {
      const double gx = p->verts[k].x, gy = p->verts[k].y;
      stroke.push_back(place((gx + (tc.style.italic ? gy * kItalicSlant : 0)) * s, -gy * s));
    }
    if (stroke.size() >= 2) gl.strokes.push_back(std::move(stroke));
  }
  if (!gl.strokes.empty()) out.glyphs.push_back(std::move(gl));
}

}  // namespace

void require_fonts() { (void)cache().get("futural"); }

std::u32string decode_utf8(const std::string& s) {
  std::u32string out;
  for (size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    int n = c < 0x80 ? 0 : (c >> 5) == 6 ? 1 : (c >> 4) == 14 ? 2 : (c >> 3) == 30 ? 3 : -1;
    if (n < 0 || i + static_cast<size_t>(n) >= s.size() + (n == 0 ? 1 : 0)) {  // bad lead byte or cut short
      out.push_back(0xFFFD);
      ++i;
      continue;
    }
    char32_t cp = n == 0 ? c : c & (0x3F >> n);
    bool ok = true;
    for (int k = 1; k <= n; ++k) {
      const unsigned char cc = static_cast<unsigned char>(s[i + static_cast<size_t>(k)]);
      if ((cc >> 6) != 2) ok = false;
      cp = (cp << 6) | (cc & 0x3F);
    }
    out.push_back(ok ? cp : 0xFFFD);
    i += ok ? static_cast<size_t>(n) + 1 : 1;
  }
  return out;
}

TextResult lay_out_text(const std::vector<TextChar>& chars, Vec2 start) {
  TextResult out;
  std::vector<Vec2> pos(chars.size());
  std::vector<double> adv(chars.size());
  std::vector<size_t> chunk_start;
  double cx = start.x, cy = start.y;
  for (size_t i = 0; i < chars.size(); ++i) {
    const TextChar& tc = chars[i];
    if (i == 0 || tc.x || tc.y) chunk_start.push_back(i);
    if (tc.x) cx = *tc.x;
    if (tc.y) cy = *tc.y;
    cx += tc.dx;
    cy += tc.dy;
    pos[i] = {cx, cy};
    adv[i] = advance(tc);
    cx += adv[i];
  }
  chunk_start.push_back(chars.size());
  for (size_t c = 0; c + 1 < chunk_start.size(); ++c) {
    const size_t a = chunk_start[c], b = chunk_start[c + 1];
    if (a >= b) continue;
    const double width = pos[b - 1].x + adv[b - 1] - pos[a].x;
    const Anchor anchor = chars[a].style.anchor;
    const double shift = anchor == Anchor::middle ? -width / 2 : anchor == Anchor::end ? -width : 0;
    for (size_t i = a; i < b; ++i) {
      const Vec2 o{pos[i].x + shift, pos[i].y};
      draw_glyph(chars[i], [o](double u, double v) { return Vec2{o.x + u, o.y + v}; }, out);
    }
  }
  return out;
}

TextResult lay_out_on_path(const std::vector<TextChar>& chars, const std::vector<Vec2>& path, double start_offset) {
  TextResult out;
  if (path.size() < 2 || chars.empty()) return out;
  std::vector<double> along(path.size(), 0);
  for (size_t k = 1; k < path.size(); ++k)
    along[k] = along[k - 1] + std::hypot(path[k].x - path[k - 1].x, path[k].y - path[k - 1].y);
  const double length = along.back();
  double total = 0;
  for (const TextChar& tc : chars) total += advance(tc) + tc.dx;
  const Anchor anchor = chars.front().style.anchor;
  double d = start_offset - (anchor == Anchor::middle ? total / 2 : anchor == Anchor::end ? total : 0);
  double shift_v = 0;
  for (const TextChar& tc : chars) {
    const double a = advance(tc);
    d += tc.dx;
    shift_v += tc.dy;
    const double mid = d + a / 2;
    d += a;
    if (mid < 0 || mid > length) continue;  // off the path: not drawn
    const size_t k = static_cast<size_t>(std::upper_bound(along.begin(), along.end(), mid) - along.begin());
    const size_t i = std::clamp<size_t>(k, 1, path.size() - 1);
    const double seg = along[i] - along[i - 1];
    const double t = seg > 0 ? (mid - along[i - 1]) / seg : 0;
    const Vec2 p{path[i - 1].x + t * (path[i].x - path[i - 1].x), path[i - 1].y + t * (path[i].y - path[i - 1].y)};
    const Vec2 dir = seg > 0 ? Vec2{(path[i].x - path[i - 1].x) / seg, (path[i].y - path[i - 1].y) / seg} : Vec2{1, 0};
    const Vec2 nrm{-dir.y, dir.x};  // "down" for text running along dir on a y-down page
    draw_glyph(tc, [&](double u, double v) {
      const double uu = u - a / 2, vv = v + shift_v;
      return Vec2{p.x + uu * dir.x + vv * nrm.x, p.y + uu * dir.y + vv * nrm.y};
    }, out);
  }
  return out;
}

TextResult lay_out_in_box(const std::vector<TextChar>& chars, const Rect& box) {
  TextResult out;
  if (chars.empty()) return out;
  double x = box.x0, line_h = 1.25 * chars.front().style.size, baseline = box.y0 + chars.front().style.size;
  auto new_line = [&](const TextChar& next) {
    x = box.x0;
    baseline += line_h;
    line_h = 1.25 * next.style.size;
  };
  size_t i = 0;
  while (i < chars.size()) {
    if (chars[i].paragraph && i > 0) new_line(chars[i]);
    if (chars[i].code == ' ') {
      if (x > box.x0) x += advance(chars[i]);
      ++i;
      continue;
    }
    size_t j = i;
    double width = 0;
    while (j < chars.size() && chars[j].code != ' ' && (j == i || !chars[j].paragraph)) width += advance(chars[j++]);
    if (x > box.x0 && x + width > box.x1) new_line(chars[i]);
    if (baseline > box.y1) break;  // the box is full
    for (; i < j; ++i) {
      const Vec2 o{x, baseline};
      draw_glyph(chars[i], [o](double u, double v) { return Vec2{o.x + u, o.y + v}; }, out);
      x += advance(chars[i]);
    }
  }
  return out;
}

}  // namespace stipplot::svgtext
