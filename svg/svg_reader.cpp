#include "svg/svg_reader.hpp"

#include <expat.h>
#include <tinyxml2.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <string_view>
#include <thread>
#include <unordered_set>
#include <vector>

#include "geometry/affine.hpp"
#include "svg/text_layout.hpp"
#include "util/threads.hpp"
#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kMmPerPx = 25.4 / 96.0;

struct Paint {
  bool none = false;
  Color color = colors::black;
  bool pattern = false;  // a gradient or pattern (url(...)): drawn in black, never hatched solid
};

struct Style {
  Paint stroke{true, colors::black};  // SVG default: no stroke
  Paint fill{false, colors::black};   // SVG default: black fill
  double stroke_width = 1;            // user units of the element that set it
  double stroke_width_mm = -1;        // resolved with the transform in effect where set; -1 unset
  bool visible = true;
  FillRule fill_rule = FillRule::nonzero;
  svgtext::TextStyle text;            // font size (user units), family, weight, slant, anchor
  bool preserve_space = false;        // xml:space="preserve"
};

class Reader {
  friend class StreamReader;

 public:
  Reader(const std::string& name, const SvgReadOptions& opt) : name_(name), opt_(opt) {}

  size_t missing_glyphs() const { return missing_glyphs_; }

  // What a container hands its children: where they land on the page, their inherited
  // style and the layer they are drawn in (pointing at a label the caller keeps alive).
  struct Context {
    Affine ctm;
    Style style;
    const std::string* layer = nullptr;
    std::string label;  // a layer's name when this container started the layer
  };

  Drawing run(const tinyxml2::XMLDocument& doc) {
    const tinyxml2::XMLElement* root = doc.RootElement();
    Context ctx;
    if (!begin(root, ctx)) return drawing_;
    walk_children(root, ctx.ctm, ctx.style, nullptr);
    return finish();
  }

  // The root <svg>: the page's transform and style; false when nothing is drawn at all.
  bool begin(const tinyxml2::XMLElement* root, Context& ctx) {
    if (!root || std::strcmp(local(root->Name()), "svg") != 0)
      throw UserError(name_ + ": not an SVG file (the root element is not <svg>)");
    ctx.ctm = compose(root, Affine{}, root_transform(root));
    ctx.style.stroke_width_mm = -1;
    apply_style(root, ctx.style, ctx.ctm);
    return !display_none(root);
  }

  Drawing finish() {
    finish_layers();
    return std::move(drawing_);
  }

  static bool is_container(const char* tag) {
    return std::strcmp(tag, "g") == 0 || std::strcmp(tag, "svg") == 0 || std::strcmp(tag, "a") == 0;
  }

  // A container element (is_container) met in `parent`: the context of its children into
  // `child`; false when they are not drawn.
  bool enter(const tinyxml2::XMLElement* e, const Context& parent, Context& child) {
    child.ctm = parent.ctm;
    child.style = parent.style;
    child.layer = parent.layer;
    const char* tag = local(e->Name());
    return open(e, tag, child.ctm, child.style) && container(e, tag, child.ctm, child.layer, child.label);
  }

 private:
  struct LayerInfo {
    size_t index;
    bool pen_set = false;
  };

  // ---------- errors and attributes ----------
  [[noreturn]] void fail(const tinyxml2::XMLElement* e, const std::string& what) const {
    if (!e) throw UserError(name_ + ": " + what);
    throw UserError(name_ + " line " + std::to_string(line_of(e)) + ": <" + e->Name() + "> " + what);
  }

  // Elements the stream built carry their line in the user data (tinyxml2 counts lines only
  // for what it parsed itself).
  static int line_of(const tinyxml2::XMLElement* e) {
    if (const void* u = e->GetUserData()) return static_cast<int>(reinterpret_cast<intptr_t>(u));
    return e->GetLineNum();
  }

  static const char* local(const char* name) {
    const char* colon = std::strrchr(name, ':');
    return colon ? colon + 1 : name;
  }

  // A plain number attribute (with an optional unit converted to user units = px).
  double length_attr(const tinyxml2::XMLElement* e, const char* attr, double fallback) const {
    const char* v = e->Attribute(attr);
    if (!v) return fallback;
    double out;
    if (!parse_length(v, 1.0 / kMmPerPx, out)) fail(e, std::string(attr) + "=\"" + v + "\" is not a number or length");
    return out;
  }

  // "12.5", "12.5mm", "1in"... in units where 1 mm = mm_unit. False on anything else.
  // The number and unit are read by the one length grammar (util/units.hpp); the units
  // are CSS's, where a bare number is a px of 1/96 in.
  static bool parse_length(const char* text, double mm_unit, double& out) {
    double v = 0;
    std::string unit;
    if (!split_number_unit(text, v, unit) || !std::isfinite(v)) return false;
    double px_per_unit;
    if (unit.empty() || unit == "px") px_per_unit = 1;
    else if (unit == "mm") px_per_unit = 1 / kMmPerPx;
    else if (unit == "cm") px_per_unit = 10 / kMmPerPx;
    else if (unit == "in") px_per_unit = 96;
    else if (unit == "pt") px_per_unit = 96.0 / 72.0;
    else if (unit == "pc") px_per_unit = 16;
    else return false;
    // v in px, then into the requested unit
    out = v * px_per_unit * kMmPerPx * mm_unit;
    return true;
  }

  // The CSS value of a property: style="..." wins over the presentation attribute.
  static std::optional<std::string> property(const tinyxml2::XMLElement* e, const char* prop) {
    if (const char* st = e->Attribute("style")) {
      std::string s = st;
      size_t pos = 0;
      std::optional<std::string> found;
      while (pos < s.size()) {
        size_t semi = s.find(';', pos);
        if (semi == std::string::npos) semi = s.size();
        std::string decl = s.substr(pos, semi - pos);
        size_t colon = decl.find(':');
        if (colon != std::string::npos) {
          std::string k = trim(decl.substr(0, colon)), v = trim(decl.substr(colon + 1));
          if (k == prop) found = v;
        }
        pos = semi + 1;
      }
      if (found) return found;
    }
    if (const char* a = e->Attribute(prop)) return trim(a);
    return std::nullopt;
  }

  // An element's properties read once: its style="..." declarations (the last of a name
  // wins, and wins over the attribute) and its attributes' names and values. Styling asks
  // for 17 properties an element; asking the element each time scanned its attributes
  // twice for each (a quarter of reading a 1M-dot SVG). Same answers as property().
  class Declared {
   public:
    explicit Declared(const tinyxml2::XMLElement* e) {
      const char* style = nullptr;
      attrs_.reserve(8);  // one allocation for most elements, not one per doubling
      for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
        if (!style && std::strcmp(a->Name(), "style") == 0) style = a->Value();
        else attrs_.emplace_back(a->Name(), a->Value());
      }
      if (!style) return;
      const std::string s = style;
      size_t pos = 0;
      while (pos < s.size()) {
        size_t semi = s.find(';', pos);
        if (semi == std::string::npos) semi = s.size();
        const std::string decl = s.substr(pos, semi - pos);
        const size_t colon = decl.find(':');
        if (colon != std::string::npos) decls_.emplace_back(trim(decl.substr(0, colon)), trim(decl.substr(colon + 1)));
        pos = semi + 1;
      }
    }
    std::optional<std::string> operator()(const char* prop) const {
      for (auto it = decls_.rbegin(); it != decls_.rend(); ++it)
        if (it->first == prop) return it->second;
      for (const auto& [name, value] : attrs_)
        if (name[0] == prop[0] && std::strcmp(name, prop) == 0) return trim(value);
      return std::nullopt;
    }

   private:
    std::vector<std::pair<std::string, std::string>> decls_;
    std::vector<std::pair<const char*, const char*>> attrs_;
  };

  static std::string trim(std::string s) {
    size_t b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
    if (b == std::string::npos) return "";
    s = s.substr(b, e - b + 1);
    // "!important" does not change what we draw
    size_t imp = s.find("!important");
    if (imp != std::string::npos) s = trim(s.substr(0, imp));
    return s;
  }

  static bool display_none(const tinyxml2::XMLElement* e) {
    auto d = property(e, "display");
    return d && *d == "none";
  }

  void apply_style(const tinyxml2::XMLElement* e, Style& s, const Affine& ctm) const {
    const Declared property(e);
    auto paint = [&](const char* prop, Paint& p) {
      auto v = property(prop);
      if (!v || *v == "inherit" || v->empty()) return;
      if (*v == "none" || *v == "transparent") {
        p.none = true;
        return;
      }
      p.none = false;
      p.pattern = v->rfind("url(", 0) == 0;
      Color c;
      if (*v == "currentColor" || p.pattern) c = colors::black;  // gradients: plot in black
      else if (!Color::try_parse(*v, c)) fail(e, std::string(prop) + ": not a colour: '" + *v + "'");
      p.color = c;
    };
    paint("stroke", s.stroke);
    paint("fill", s.fill);
    if (auto w = property("stroke-width"); w && *w != "inherit") {
      double v;
      if (!parse_length(w->c_str(), 1.0 / kMmPerPx, v) || v < 0) fail(e, "stroke-width: bad value '" + *w + "'");
      s.stroke_width = v;
      s.stroke_width_mm = v * std::sqrt(std::fabs(ctm.det()));
    }
    if (const char* dw = e->Attribute("data-pen-width")) {  // stipplot's own layers
      double v;
      if (!parse_length(dw, 1.0 / kMmPerPx, v) || v < 0) fail(e, "data-pen-width: bad value");
      s.stroke_width_mm = v * std::sqrt(std::fabs(ctm.det()));
    }
    if (auto v = property("visibility")) {
      if (*v == "hidden" || *v == "collapse") s.visible = false;
      else if (*v == "visible") s.visible = true;
    }
    // Fully transparent paint is no paint (hit areas, guides).
    if (auto v = property("fill-opacity"); v && opacity_zero(*v)) s.fill.none = true;
    if (auto v = property("stroke-opacity"); v && opacity_zero(*v)) s.stroke.none = true;
    if (auto v = property("opacity"); v && opacity_zero(*v)) s.visible = false;
    if (auto v = property("fill-rule")) {
      if (*v == "evenodd") s.fill_rule = FillRule::evenodd;
      else if (*v == "nonzero") s.fill_rule = FillRule::nonzero;
    }
    if (const char* sp = e->Attribute("xml:space")) s.preserve_space = std::strcmp(sp, "preserve") == 0;
    apply_text_style(e, property, s.text);
  }

  static bool opacity_zero(const std::string& v) {
    double x;
    std::string unit;
    return split_number_unit(v, x, unit) && (unit.empty() ? x : unit == "%" ? x / 100 : 1) <= 0;
  }

  // font-size (a length, em or % of the inherited size, or a CSS keyword), font-family,
  // font-weight, font-style, text-anchor.
  void apply_text_style(const tinyxml2::XMLElement* e, const Declared& property, svgtext::TextStyle& t) const {
    if (auto v = property("font-size"); v && *v != "inherit" && !v->empty()) {
      static const std::pair<const char*, double> keywords[] = {{"xx-small", 9},  {"x-small", 10}, {"small", 13},
                                                                {"medium", 16},   {"large", 18},   {"x-large", 24},
                                                                {"xx-large", 32}, {"smaller", -0.8}, {"larger", -1.2}};
      double x = 0;
      std::string unit;
      bool done = false;
      for (const auto& [name, size] : keywords)
        if (*v == name) t.size = size > 0 ? size : -size * t.size, done = true;
      if (!done && v->back() == '%' && split_number_unit(v->substr(0, v->size() - 1), x, unit) && unit.empty()) {
        t.size *= x / 100;
      } else if (!done && split_number_unit(*v, x, unit) && unit == "em") {
        t.size *= x;
      } else if (!done) {
        double px;
        if (!parse_length(v->c_str(), 1.0 / kMmPerPx, px) || !(px >= 0)) fail(e, "font-size: bad value '" + *v + "'");
        t.size = px;
      }
    }
    if (auto v = property("font-family"); v && *v != "inherit") t.family = *v;
    if (auto v = property("font-weight"); v && *v != "inherit") {
      double w = 0;
      std::string unit;
      t.bold = *v == "bold" || *v == "bolder" || (split_number_unit(*v, w, unit) && unit.empty() && w >= 600);
    }
    if (auto v = property("font-style"); v && *v != "inherit") t.italic = *v == "italic" || *v == "oblique";
    if (auto v = property("text-anchor"); v && *v != "inherit") {
      t.anchor = *v == "middle" ? svgtext::Anchor::middle : *v == "end" ? svgtext::Anchor::end : svgtext::Anchor::start;
    }
  }

  // ---------- root: units and viewBox ----------
  Affine root_transform(const tinyxml2::XMLElement* root) {
    auto len_mm = [&](const char* attr) -> std::optional<double> {
      const char* v = root->Attribute(attr);
      if (!v) return std::nullopt;
      std::string t = trim(v);
      if (!t.empty() && t.back() == '%') return std::nullopt;  // relative to a viewer: use the viewBox
      double mm;
      if (!parse_length(v, 1.0, mm) || mm <= 0) fail(root, std::string(attr) + "=\"" + v + "\" is not a positive length");
      return mm;
    };
    std::optional<double> w = len_mm("width"), h = len_mm("height");
    std::optional<std::array<double, 4>> vb;
    if (const char* v = root->Attribute("viewBox")) {
      std::array<double, 4> a{};
      NumberScanner sc(v);
      for (double& x : a)
        if (!sc.number(x)) fail(root, std::string("viewBox=\"") + v + "\" needs four numbers");
      if (a[2] <= 0 || a[3] <= 0) fail(root, "viewBox width and height must be positive");
      vb = a;
    }
    Affine t;
    if (vb) {
      const auto [minx, miny, vw, vh] = *vb;
      if (!w && !h) {
        w = vw * kMmPerPx;
        h = vh * kMmPerPx;
      } else if (!w) {
        w = *h * vw / vh;
      } else if (!h) {
        h = *w * vh / vw;
      }
      double sx = *w / vw, sy = *h / vh;
      std::string par = root->Attribute("preserveAspectRatio") ? trim(root->Attribute("preserveAspectRatio")) : "";
      if (par.rfind("none", 0) != 0) {
        double s = par.find("slice") != std::string::npos ? std::max(sx, sy) : std::min(sx, sy);
        double ox = (*w - vw * s) / 2, oy = (*h - vh * s) / 2;  // xMidYMid
        if (par.find("xMin") != std::string::npos) ox = 0;
        if (par.find("xMax") != std::string::npos) ox = *w - vw * s;
        if (par.find("YMin") != std::string::npos) oy = 0;
        if (par.find("YMax") != std::string::npos) oy = *h - vh * s;
        t = {s, 0, 0, s, ox - minx * s, oy - miny * s};
      } else {
        t = {sx, 0, 0, sy, -minx * sx, -miny * sy};
      }
    } else {
      t = {kMmPerPx, 0, 0, kMmPerPx, 0, 0};
      if (!w) w = 210;
      if (!h) h = 297;
    }
    drawing_.page.width_mm = *w;
    drawing_.page.height_mm = *h;
    return t;
  }

  // ---------- numbers ----------
  class NumberScanner {
   public:
    explicit NumberScanner(const char* s) : p_(s) {}
    void skip_sep() {
      while (*p_ && (std::isspace(static_cast<unsigned char>(*p_)) || *p_ == ',')) ++p_;
    }
    void skip_ws() {
      while (*p_ && std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    }
    bool at_end() {
      skip_sep();
      return *p_ == '\0';
    }
    char peek() {
      skip_sep();
      return *p_;
    }
    bool next_is_number() {
      char c = peek();
      return c == '-' || c == '+' || c == '.' || (c >= '0' && c <= '9');
    }
    char take() { return *p_ ? *p_++ : '\0'; }
    // SVG number grammar by hand: "1.5.5" is 1.5 then .5, "1-2" is 1 then -2.
    bool number(double& out) {
      skip_sep();
      const char* s = p_;
      const char* q = p_;
      if (*q == '+' || *q == '-') ++q;
      bool digits = false;
      while (*q >= '0' && *q <= '9') ++q, digits = true;
      if (*q == '.') {
        ++q;
        while (*q >= '0' && *q <= '9') ++q, digits = true;
      }
      if (!digits) return false;
      if (*q == 'e' || *q == 'E') {
        const char* r = q + 1;
        if (*r == '+' || *r == '-') ++r;
        if (*r >= '0' && *r <= '9') {
          while (*r >= '0' && *r <= '9') ++r;
          q = r;
        }
      }
      std::string tok(s, q);
      out = std::strtod(tok.c_str(), nullptr);
      if (!std::isfinite(out)) return false;
      p_ = q;
      return true;
    }
    // Arc flags are single characters and may run into the next number ("a1 1 0 01 2 3").
    bool flag(bool& out) {
      skip_sep();
      if (*p_ == '0' || *p_ == '1') {
        out = *p_ == '1';
        ++p_;
        return true;
      }
      return false;
    }
    const char* rest() const { return p_; }

   private:
    const char* p_;
  };

  // ---------- transforms ----------
  // `outer` after `inner`, refused when the product is no longer a sane map of the page:
  // a non-finite entry, a stretch beyond 1e9 or a shift beyond the coordinate bound.
  Affine compose(const tinyxml2::XMLElement* e, const Affine& outer, const Affine& inner) const {
    const Affine m = outer * inner;
    constexpr double kMaxStretch = 1e9;
    const bool sane = std::fabs(m.a) <= kMaxStretch && std::fabs(m.b) <= kMaxStretch &&
                      std::fabs(m.c) <= kMaxStretch && std::fabs(m.d) <= kMaxStretch &&
                      std::fabs(m.e) <= kMaxCoordinateMm && std::fabs(m.f) <= kMaxCoordinateMm;
    if (!sane)
      fail(e, "transform makes a map of the page that is not finite or stretches beyond 1e9 "
              "(or moves beyond +-1000000 mm)");
    return m;
  }

  Affine parse_transform(const tinyxml2::XMLElement* e, const char* text) const {
    Affine total;
    const char* p = text;
    auto bad = [&](const std::string& why) { fail(e, std::string("transform=\"") + text + "\": " + why); };
    while (true) {
      while (*p && (std::isspace(static_cast<unsigned char>(*p)) || *p == ',')) ++p;
      if (!*p) break;
      const char* nb = p;
      while (std::isalpha(static_cast<unsigned char>(*p))) ++p;
      std::string fn(nb, p);
      while (std::isspace(static_cast<unsigned char>(*p))) ++p;
      if (fn.empty() || *p != '(') bad("expected a function such as translate(...)");
      const char* close = std::strchr(p, ')');
      if (!close) bad("missing ')'");
      std::string args(p + 1, close);
      p = close + 1;
      std::vector<double> v;
      NumberScanner sc(args.c_str());
      double x;
      while (sc.number(x)) v.push_back(x);
      if (!sc.at_end()) bad("bad number in " + fn + "(" + args + ")");
      Affine m;
      auto nargs = [&](std::initializer_list<size_t> ok) {
        if (std::find(ok.begin(), ok.end(), v.size()) == ok.end()) bad(fn + " takes a different number of values");
      };
      double rad;
      if (fn == "matrix") {
        nargs({6});
        m = {v[0], v[1], v[2], v[3], v[4], v[5]};
      } else if (fn == "translate") {
        nargs({1, 2});
        m.e = v[0];
        m.f = v.size() > 1 ? v[1] : 0;
      } else if (fn == "scale") {
        nargs({1, 2});
        m.a = v[0];
        m.d = v.size() > 1 ? v[1] : v[0];
      } else if (fn == "rotate") {
        nargs({1, 3});
        rad = std::fmod(v[0], 360.0) * kPi / 180;  // rotate(1e308) would overflow to inf, cos(inf) NaN
        Affine r{std::cos(rad), std::sin(rad), -std::sin(rad), std::cos(rad), 0, 0};
        if (v.size() == 3) {
          Affine to{1, 0, 0, 1, v[1], v[2]}, back{1, 0, 0, 1, -v[1], -v[2]};
          m = to * r * back;
        } else {
          m = r;
        }
      } else if (fn == "skewX") {
        nargs({1});
        m.c = std::tan(std::fmod(v[0], 360.0) * kPi / 180);
      } else if (fn == "skewY") {
        nargs({1});
        m.b = std::tan(std::fmod(v[0], 360.0) * kPi / 180);
      } else {
        bad("unknown function '" + fn + "'");
      }
      total = total * m;
    }
    return total;
  }

  // ---------- tree walk ----------
  void walk_children(const tinyxml2::XMLElement* parent, const Affine& ctm, const Style& style,
                     const std::string* layer) {
    for (const tinyxml2::XMLElement* e = parent->FirstChildElement(); e; e = e->NextSiblingElement())
      walk(e, ctm, style, layer);
  }

  // The element's own transform and style on top of its parent's; false when nothing of
  // it is drawn (an element that is never drawn, display:none).
  bool open(const tinyxml2::XMLElement* e, const char* tag, Affine& ctm, Style& style) {
    // Sorted, for a binary search: every element of a large drawing asks.
    static constexpr std::string_view kSkip[] = {
        "clipPath", "defs",    "desc",    "filter", "flowRegion", "foreignObject", "image",  "linearGradient",
        "marker",   "mask",    "metadata", "namedview", "pattern", "radialGradient", "script", "style",
        "switch",   "symbol",  "title"};
    static_assert(std::is_sorted(std::begin(kSkip), std::end(kSkip)));
    if (std::binary_search(std::begin(kSkip), std::end(kSkip), std::string_view(tag))) return false;
    if (display_none(e)) return false;
    // The document's own elements are already in memory; only <use> multiplies them.
    if (use_depth_ > 0 && ++use_copies_ > opt_.max_use_copies)
      fail(e, "is one <use> copy too many: more than " + std::to_string(opt_.max_use_copies) +
                  " elements drawn through <use> (nested <use> multiply)");
    element_ = e;
    if (const char* t = e->Attribute("transform")) ctm = compose(e, ctm, parse_transform(e, t));
    apply_style(e, style, ctm);
    return true;
  }

  // A g, svg or a after open(): the layer its children are drawn in (an Inkscape layer
  // starts one, named into `label`) and a nested svg's offset; false when the layer is
  // not for plotting.
  bool container(const tinyxml2::XMLElement* e, const char* tag, Affine& ctm, const std::string*& layer,
                 std::string& label) {
    const char* mode = e->Attribute("inkscape:groupmode");
    if (!layer && mode && std::strcmp(mode, "layer") == 0) {
      const char* name = e->Attribute("inkscape:label");
      if (!name) name = e->Attribute("id");
      label = name ? trim(name) : "layer";
      if (!label.empty() && label[0] == '%') return false;  // not for plotting
      layer = &label;
    }
    if (std::strcmp(tag, "svg") == 0 && e != e->GetDocument()->RootElement())
      ctm = compose(e, ctm, Affine{1, 0, 0, 1, length_attr(e, "x", 0), length_attr(e, "y", 0)});
    return true;
  }

  void walk(const tinyxml2::XMLElement* e, Affine ctm, Style style, const std::string* layer) {
    const char* tag = local(e->Name());
    if (!open(e, tag, ctm, style)) return;
    if (is_container(tag)) {
      std::string label;
      if (container(e, tag, ctm, layer, label)) walk_children(e, ctm, style, layer);
      return;
    }
    if (std::strcmp(tag, "use") == 0) {
      use(e, ctm, style, layer);
      return;
    }
    if (std::strcmp(tag, "text") == 0) {
      text(e, ctm, style, layer);
      return;
    }
    if (std::strcmp(tag, "flowRoot") == 0) {
      flow_root(e, ctm, style, layer);
      return;
    }
    if (!style.visible || (style.stroke.none && style.fill.none)) return;  // nothing shows

    shape_ = {};
    if (std::strcmp(tag, "circle") == 0 || std::strcmp(tag, "ellipse") == 0) {
      if (circle_or_ellipse(e, tag[0] == 'c', ctm, style, layer)) return;
    } else if (!build_shape(e, tag, ctm)) {
      return;  // unknown elements draw nothing
    }
    flush_current();
    if (!shape_.empty()) add_shape(style, layer, std::strcmp(tag, "line") != 0);
  }

  // The outline of a path, line, polyline, polygon or rect into shape_ (page mm); false for
  // any other element.
  bool build_shape(const tinyxml2::XMLElement* e, const char* tag, const Affine& ctm) {
    if (std::strcmp(tag, "path") == 0) {
      const char* d = e->Attribute("d");
      if (d) path(e, d, ctm);
    } else if (std::strcmp(tag, "line") == 0) {
      move({length_attr(e, "x1", 0), length_attr(e, "y1", 0)}, ctm);
      line({length_attr(e, "x2", 0), length_attr(e, "y2", 0)}, ctm);
    } else if (std::strcmp(tag, "polyline") == 0 || std::strcmp(tag, "polygon") == 0) {
      polyline(e, ctm, tag[4] == 'g');
    } else if (std::strcmp(tag, "rect") == 0) {
      rect(e, ctm);
    } else if (std::strcmp(tag, "ellipse") == 0 || std::strcmp(tag, "circle") == 0) {
      const double cx = length_attr(e, "cx", 0), cy = length_attr(e, "cy", 0);
      const double rx = length_attr(e, tag[0] == 'c' ? "r" : "rx", 0), ry = length_attr(e, tag[0] == 'c' ? "r" : "ry", rx);
      if (rx > 0 && ry > 0) ellipse({cx, cy}, rx, ry, ctm);
    } else {
      return false;
    }
    return true;
  }

  // <polyline points> / <polygon points> (closed).
  void polyline(const tinyxml2::XMLElement* e, const Affine& ctm, bool polygon) {
    const char* pts = e->Attribute("points");
    if (!pts) return;
    NumberScanner sc(pts);
    std::vector<double> v;
    double x;
    while (sc.number(x)) v.push_back(x);
    if (!sc.at_end()) fail(e, std::string("points: bad number at '") + sc.rest() + "'");
    if (v.size() % 2) fail(e, "points: odd number of coordinates");
    for (size_t i = 0; i + 1 < v.size(); i += 2) {
      if (i == 0) move({v[0], v[1]}, ctm);
      else line({v[i], v[i + 1]}, ctm);
    }
    if (polygon && v.size() >= 4) close();
  }

  // <circle> / <ellipse>: a round shape of its own when the transform keeps it a circle
  // (then true: nothing left to add), else its outline into the current shape.
  bool circle_or_ellipse(const tinyxml2::XMLElement* e, bool is_circle, const Affine& ctm, const Style& style,
                         const std::string* layer) {
    double cx = length_attr(e, "cx", 0), cy = length_attr(e, "cy", 0);
    double rx, ry;
    if (is_circle) {
      rx = ry = length_attr(e, "r", 0);
    } else {
      rx = length_attr(e, "rx", -1);
      ry = length_attr(e, "ry", -1);
      if (rx < 0) rx = ry;  // SVG 2 "auto"
      if (ry < 0) ry = rx;
    }
    if (rx < 0 || ry < 0) fail(e, "negative radius");
    if (rx <= 0 || ry <= 0) return true;  // not rendered
    if (rx == ry && ctm.is_similarity()) {
      round_shape(e, ctm.apply({cx, cy}), rx * std::sqrt(std::fabs(ctm.det())), style, layer);
      return true;
    }
    ellipse({cx, cy}, rx, ry, ctm);
    return false;
  }

  // <use href="#id" x y>: the referenced element (a <symbol>'s children) drawn here.
  void use(const tinyxml2::XMLElement* e, const Affine& ctm, const Style& style, const std::string* layer) {
    const char* href = e->Attribute("href");
    if (!href) href = e->Attribute("xlink:href");
    if (!href || href[0] != '#') return;
    if (ids_.empty()) index_ids(e->GetDocument()->RootElement());
    auto it = ids_.find(href + 1);
    if (it == ids_.end()) fail(e, std::string("href=\"") + href + "\" names no element");
    if (use_depth_ >= 16) fail(e, "<use> nested too deeply (a reference cycle?)");
    ++use_depth_;
    Affine t = compose(e, ctm, Affine{1, 0, 0, 1, length_attr(e, "x", 0), length_attr(e, "y", 0)});
    const tinyxml2::XMLElement* target = it->second;
    if (std::strcmp(local(target->Name()), "symbol") == 0) {
      Style st = style;
      apply_style(target, st, t);
      walk_children(target, t, st, layer);
    } else {
      walk(target, t, style, layer);
    }
    --use_depth_;
  }

  void index_ids(const tinyxml2::XMLElement* e) {
    for (; e; e = e->NextSiblingElement()) {
      if (const char* id = e->Attribute("id")) ids_.emplace(id, e);
      index_ids(e->FirstChildElement());
    }
  }

  // ---------- geometry builders (everything lands in page mm) ----------
  void move(Vec2 user, const Affine& ctm) {
    flush_current();
    push(ctm.apply(user));
  }
  void line(Vec2 user, const Affine& ctm) { push(ctm.apply(user)); }
  void push(Vec2 p) {
    if (!cur_.empty() && cur_.back() == p) return;
    check_point(p);
    if (++points_ > opt_.max_points)
      fail(element_, "makes the drawing more than " + std::to_string(opt_.max_points) +
                         " points (flattened curves counted; raise --tolerance?)");
    cur_.push_back(p);
  }
  void check_point(Vec2 p) const {
    if (!(std::fabs(p.x) <= kMaxCoordinateMm && std::fabs(p.y) <= kMaxCoordinateMm))
      fail(element_, "has a point outside +-1000000 mm of the page's origin (or not a number)");
  }
  void close() {
    if (cur_.size() >= 2 && !(cur_.front() == cur_.back())) cur_.push_back(cur_.front());
  }
  void flush_current() {
    if (cur_.size() >= 2) shape_.push_back({std::move(cur_)});
    cur_.clear();
  }

  // Cubic Bezier in page mm, flattened by recursive subdivision until both control points
  // lie within the tolerance of the chord (the curve stays inside their hull).
  void cubic(Vec2 p0, Vec2 p1, Vec2 p2, Vec2 p3, int depth = 0) {
    auto dist_to_chord = [&](Vec2 q) {
      double dx = p3.x - p0.x, dy = p3.y - p0.y, len = std::hypot(dx, dy);
      if (len < 1e-12) return std::hypot(q.x - p0.x, q.y - p0.y);
      return std::fabs((q.x - p0.x) * dy - (q.y - p0.y) * dx) / len;
    };
    if (depth >= 18 || std::max(dist_to_chord(p1), dist_to_chord(p2)) <= opt_.tolerance_mm) {
      push(p3);
      return;
    }
    auto mid = [](Vec2 a, Vec2 b) { return Vec2{(a.x + b.x) / 2, (a.y + b.y) / 2}; };
    Vec2 a = mid(p0, p1), b = mid(p1, p2), c = mid(p2, p3), ab = mid(a, b), bc = mid(b, c), m = mid(ab, bc);
    cubic(p0, a, ab, m, depth + 1);
    cubic(m, bc, c, p3, depth + 1);
  }

  // Points on an ellipse (centre c, radii rx ry, x-axis rotation phi, all user units) from
  // angle t0 over dt, as many as keep the chord error within tolerance on the page.
  // The last point is `end` exactly (page mm), so closed shapes close and arcs meet the next segment.
  void arc_points(Vec2 c, double rx, double ry, double phi, double t0, double dt, const Affine& ctm, Vec2 end) {
    double r_mm = std::max(rx, ry) * ctm.max_scale();
    double step = kPi / 2;
    if (r_mm > opt_.tolerance_mm) step = std::min(step, 2 * std::acos(1 - opt_.tolerance_mm / r_mm));
    int n = static_cast<int>(std::clamp(std::ceil(std::fabs(dt) / step), 1.0, 100000.0));
    if (points_ + static_cast<size_t>(n) > opt_.max_points)  // before a single point is made
      fail(element_, "makes the drawing more than " + std::to_string(opt_.max_points) +
                         " points (flattened curves counted; raise --tolerance?)");
    double cp = std::cos(phi), sp = std::sin(phi);
    for (int i = 1; i < n; ++i) {
      double t = t0 + dt * i / n;
      double x = rx * std::cos(t), y = ry * std::sin(t);
      push(ctm.apply({c.x + cp * x - sp * y, c.y + sp * x + cp * y}));
    }
    push(end);
  }

  void ellipse(Vec2 c, double rx, double ry, const Affine& ctm) {
    move({c.x + rx, c.y}, ctm);
    arc_points(c, rx, ry, 0, 0, 2 * kPi, ctm, cur_.front());
  }

  // SVG arc from the current point p0 to p1 (implementation notes, "endpoint to centre").
  void arc(Vec2 p0, double rx, double ry, double phi_deg, bool large, bool sweep, Vec2 p1, const Affine& ctm) {
    if (p0 == p1) return;
    rx = std::fabs(rx);
    ry = std::fabs(ry);
    if (rx == 0 || ry == 0) {
      line(p1, ctm);
      return;
    }
    double phi = std::fmod(phi_deg, 360.0) * kPi / 180;
    double cp = std::cos(phi), sp = std::sin(phi);
    double dx = (p0.x - p1.x) / 2, dy = (p0.y - p1.y) / 2;
    double x1 = cp * dx + sp * dy, y1 = -sp * dx + cp * dy;
    double lambda = (x1 * x1) / (rx * rx) + (y1 * y1) / (ry * ry);
    if (lambda > 1) {  // radii too small: scale them up just enough
      double s = std::sqrt(lambda);
      rx *= s;
      ry *= s;
    }
    double num = rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1;
    double den = rx * rx * y1 * y1 + ry * ry * x1 * x1;
    double coef = den > 0 ? std::sqrt(std::max(0.0, num / den)) : 0;
    if (large == sweep) coef = -coef;
    double cxp = coef * rx * y1 / ry, cyp = -coef * ry * x1 / rx;
    Vec2 c{cp * cxp - sp * cyp + (p0.x + p1.x) / 2, sp * cxp + cp * cyp + (p0.y + p1.y) / 2};
    auto angle = [](double ux, double uy, double vx, double vy) {
      return std::atan2(ux * vy - uy * vx, ux * vx + uy * vy);
    };
    double t1 = angle(1, 0, (x1 - cxp) / rx, (y1 - cyp) / ry);
    double dt = angle((x1 - cxp) / rx, (y1 - cyp) / ry, (-x1 - cxp) / rx, (-y1 - cyp) / ry);
    if (!sweep && dt > 0) dt -= 2 * kPi;
    if (sweep && dt < 0) dt += 2 * kPi;
    arc_points(c, rx, ry, phi, t1, dt, ctm, ctm.apply(p1));
  }

  void rect(const tinyxml2::XMLElement* e, const Affine& ctm) {
    double x = length_attr(e, "x", 0), y = length_attr(e, "y", 0);
    double w = length_attr(e, "width", 0), h = length_attr(e, "height", 0);
    if (w < 0 || h < 0) fail(e, "negative width or height");
    if (w == 0 || h == 0) return;
    double rx = length_attr(e, "rx", -1), ry = length_attr(e, "ry", -1);
    if (rx < 0 && ry < 0) rx = ry = 0;
    else if (rx < 0) rx = ry;
    else if (ry < 0) ry = rx;
    rx = std::min(rx, w / 2);
    ry = std::min(ry, h / 2);
    if (rx == 0 || ry == 0) {
      move({x, y}, ctm);
      line({x + w, y}, ctm);
      line({x + w, y + h}, ctm);
      line({x, y + h}, ctm);
      close();
      return;
    }
    move({x + rx, y}, ctm);
    line({x + w - rx, y}, ctm);
    arc({x + w - rx, y}, rx, ry, 0, false, true, {x + w, y + ry}, ctm);
    line({x + w, y + h - ry}, ctm);
    arc({x + w, y + h - ry}, rx, ry, 0, false, true, {x + w - rx, y + h}, ctm);
    line({x + rx, y + h}, ctm);
    arc({x + rx, y + h}, rx, ry, 0, false, true, {x, y + h - ry}, ctm);
    line({x, y + ry}, ctm);
    arc({x, y + ry}, rx, ry, 0, false, true, {x + rx, y}, ctm);
    close();
  }

  // The path data grammar as one loop over commands: every command reads and moves the
  // same cursor (position, subpath start, last control point), so the switch stays whole.
  void path(const tinyxml2::XMLElement* e, const char* d, const Affine& ctm) {
    NumberScanner sc(d);
    Vec2 pos{0, 0}, start{0, 0}, ctrl{0, 0};
    char prev = ' ';
    char cmd = ' ';
    auto bad = [&](const std::string& why) {
      std::string at = sc.rest();
      if (at.size() > 20) at = at.substr(0, 20) + "...";
      fail(e, "d: " + why + " at '" + at + "'");
    };
    auto num = [&]() {
      double v;
      if (!sc.number(v)) bad(std::string("command ") + cmd + " needs a number");
      return v;
    };
    auto pt = [&](bool rel) {
      double x = num(), y = num();
      return rel ? Vec2{pos.x + x, pos.y + y} : Vec2{x, y};
    };
    while (!sc.at_end()) {
      if (sc.next_is_number()) {
        if (cmd == ' ') bad("path data must start with M");
        if (cmd == 'M') cmd = 'L';
        else if (cmd == 'm') cmd = 'l';
        else if (cmd == 'Z' || cmd == 'z') bad("numbers after Z");
      } else {
        cmd = sc.take();
        if (prev == ' ' && cmd != 'M' && cmd != 'm') bad("path data must start with M");
      }
      const bool rel = std::islower(static_cast<unsigned char>(cmd));
      const char up = static_cast<char>(std::toupper(static_cast<unsigned char>(cmd)));
      switch (up) {
        case 'M':
          pos = pt(rel);
          start = pos;
          move(pos, ctm);
          break;
        case 'L':
          pos = pt(rel);
          line(pos, ctm);
          break;
        case 'H':
          pos.x = rel ? pos.x + num() : num();
          line(pos, ctm);
          break;
        case 'V':
          pos.y = rel ? pos.y + num() : num();
          line(pos, ctm);
          break;
        case 'C': {
          Vec2 c1 = pt(rel), c2 = pt(rel), p = pt(rel);
          curve(pos, c1, c2, p, ctm);
          ctrl = c2;
          pos = p;
          break;
        }
        case 'S': {
          char pu = static_cast<char>(std::toupper(static_cast<unsigned char>(prev)));
          Vec2 c1 = (pu == 'C' || pu == 'S') ? Vec2{2 * pos.x - ctrl.x, 2 * pos.y - ctrl.y} : pos;
          Vec2 c2 = pt(rel), p = pt(rel);
          curve(pos, c1, c2, p, ctm);
          ctrl = c2;
          pos = p;
          break;
        }
        case 'Q': {
          Vec2 q = pt(rel), p = pt(rel);
          quad(pos, q, p, ctm);
          ctrl = q;
          pos = p;
          break;
        }
        case 'T': {
          char pu = static_cast<char>(std::toupper(static_cast<unsigned char>(prev)));
          Vec2 q = (pu == 'Q' || pu == 'T') ? Vec2{2 * pos.x - ctrl.x, 2 * pos.y - ctrl.y} : pos;
          Vec2 p = pt(rel);
          quad(pos, q, p, ctm);
          ctrl = q;
          pos = p;
          break;
        }
        case 'A': {
          double rx = num(), ry = num(), rot = num();
          bool large, sweep;
          if (!sc.flag(large)) bad("arc large-arc flag must be 0 or 1");
          if (!sc.flag(sweep)) bad("arc sweep flag must be 0 or 1");
          Vec2 p = pt(rel);
          if (cur_.empty()) push(ctm.apply(pos));
          arc(pos, rx, ry, rot, large, sweep, p, ctm);
          pos = p;
          break;
        }
        case 'Z':
          close();
          pos = start;
          // a drawing command after Z starts a new subpath at the start point
          flush_current();
          push(ctm.apply(pos));
          break;
        default:
          bad(std::string("unknown path command '") + cmd + "'");
      }
      prev = cmd;
    }
    flush_current();
  }

  void curve(Vec2 p0, Vec2 c1, Vec2 c2, Vec2 p, const Affine& ctm) {
    if (cur_.empty()) push(ctm.apply(p0));
    cubic(ctm.apply(p0), ctm.apply(c1), ctm.apply(c2), ctm.apply(p));
  }
  void quad(Vec2 p0, Vec2 q, Vec2 p, const Affine& ctm) {
    // degree elevation: a quadratic is the cubic with controls 2/3 of the way to q
    Vec2 c1{p0.x + 2.0 / 3 * (q.x - p0.x), p0.y + 2.0 / 3 * (q.y - p0.y)};
    Vec2 c2{p.x + 2.0 / 3 * (q.x - p.x), p.y + 2.0 / 3 * (q.y - p.y)};
    curve(p0, c1, c2, p, ctm);
  }

  // ---------- text ----------
  // Per-character positions of an element and its descendants (SVG's x, y, dx, dy lists):
  // each character takes the next value of the innermost list that has one left, and
  // every list in scope moves on by one.
  struct PositionLists {
    std::vector<std::vector<double>> x, y, dx, dy;
    std::vector<size_t> nx, ny, ndx, ndy;
  };

  std::vector<double> number_list(const tinyxml2::XMLElement* e, const char* attr) const {
    std::vector<double> v;
    const char* text = e->Attribute(attr);
    if (!text) return v;
    NumberScanner sc(text);
    double x;
    while (sc.number(x)) v.push_back(x);
    if (!sc.at_end()) fail(e, std::string(attr) + ": bad number at '" + sc.rest() + "'");
    return v;
  }

  struct TextRun {
    std::vector<svgtext::TextChar> chars;
    std::vector<Style> paints;  // TextChar::paint indexes these
    bool last_space = true;     // collapsing: drop spaces after a space (or at the start)
  };

  static std::optional<double> take(std::vector<std::vector<double>>& lists, std::vector<size_t>& next) {
    std::optional<double> v;
    for (size_t k = lists.size(); k-- > 0;)
      if (!v && next[k] < lists[k].size()) v = lists[k][next[k]];
    for (size_t& n : next) ++n;
    return v;
  }

  void add_text_chars(const std::string& utf8, const Style& style, PositionLists& pos, TextRun& run) {
    std::optional<size_t> paint;
    for (char32_t c : svgtext::decode_utf8(utf8)) {
      if (c == '\n' || c == '\r') {
        if (!style.preserve_space) continue;  // newlines vanish, or become spaces when preserved
        c = ' ';
      }
      if (c == '\t') c = ' ';
      if (c == ' ' && !style.preserve_space && run.last_space) continue;
      run.last_space = c == ' ';
      if (!paint) {
        run.paints.push_back(style);
        paint = run.paints.size() - 1;
      }
      svgtext::TextChar tc;
      tc.code = c;
      tc.style = style.text;
      tc.paint = *paint;
      tc.x = take(pos.x, pos.nx);
      tc.y = take(pos.y, pos.ny);
      tc.dx = take(pos.dx, pos.ndx).value_or(0);
      tc.dy = take(pos.dy, pos.ndy).value_or(0);
      run.chars.push_back(tc);
    }
  }

  // The characters of e's content: text, and tspan, tref, a, flowSpan, flowPara, flowDiv
  // children with their own styles and positions. A textPath child is laid out on its
  // path at once (what came before it first).
  void collect_text(const tinyxml2::XMLElement* e, const Affine& ctm, const Style& style, PositionLists& pos,
                    TextRun& run, const std::string* layer) {
    for (const tinyxml2::XMLNode* n = e->FirstChild(); n; n = n->NextSibling()) {
      if (const tinyxml2::XMLText* t = n->ToText()) {
        add_text_chars(t->Value() ? t->Value() : "", style, pos, run);
        continue;
      }
      const tinyxml2::XMLElement* c = n->ToElement();
      if (!c || display_none(c)) continue;
      const char* tag = local(c->Name());
      Style st = style;
      apply_style(c, st, ctm);
      if (std::strcmp(tag, "textPath") == 0) {
        place_text(run, ctm, layer);
        text_path(c, ctm, st, layer);
        continue;
      }
      const bool span = std::strcmp(tag, "tspan") == 0 || std::strcmp(tag, "a") == 0 ||
                        std::strcmp(tag, "flowSpan") == 0 || std::strcmp(tag, "altGlyph") == 0;
      const bool para = std::strcmp(tag, "flowPara") == 0 || std::strcmp(tag, "flowDiv") == 0;
      if (std::strcmp(tag, "tref") == 0) {
        const tinyxml2::XMLElement* target = referenced(c);
        if (target) add_text_chars(all_text(target), st, pos, run);  // its characters, placed here
        continue;
      }
      if (!span && !para) continue;
      if (para) {
        run.last_space = true;
        const size_t before = run.chars.size();
        collect_text(c, ctm, st, pos, run, layer);
        if (run.chars.size() > before) run.chars[before].paragraph = true;
        continue;
      }
      push_positions(c, pos);
      collect_text(c, ctm, st, pos, run, layer);
      pop_positions(pos);
    }
  }

  void push_positions(const tinyxml2::XMLElement* e, PositionLists& p) const {
    p.x.push_back(number_list(e, "x"));
    p.y.push_back(number_list(e, "y"));
    p.dx.push_back(number_list(e, "dx"));
    p.dy.push_back(number_list(e, "dy"));
    p.nx.push_back(0);
    p.ny.push_back(0);
    p.ndx.push_back(0);
    p.ndy.push_back(0);
  }
  static void pop_positions(PositionLists& p) {
    for (auto* v : {&p.x, &p.y, &p.dx, &p.dy}) v->pop_back();
    for (auto* v : {&p.nx, &p.ny, &p.ndx, &p.ndy}) v->pop_back();
  }

  static std::string all_text(const tinyxml2::XMLElement* e) {
    std::string out;
    for (const tinyxml2::XMLNode* n = e->FirstChild(); n; n = n->NextSibling()) {
      if (const tinyxml2::XMLText* t = n->ToText()) out += t->Value() ? t->Value() : "";
      else if (const tinyxml2::XMLElement* c = n->ToElement()) out += all_text(c);
    }
    return out;
  }

  const tinyxml2::XMLElement* referenced(const tinyxml2::XMLElement* e) {
    const char* href = e->Attribute("href");
    if (!href) href = e->Attribute("xlink:href");
    if (!href || href[0] != '#') return nullptr;
    if (ids_.empty()) index_ids(e->GetDocument()->RootElement());
    auto it = ids_.find(href + 1);
    if (it == ids_.end()) fail(e, std::string("href=\"") + href + "\" names no element");
    return it->second;
  }

  void text(const tinyxml2::XMLElement* e, const Affine& ctm, const Style& style, const std::string* layer) {
    svgtext::require_fonts();
    PositionLists pos;
    push_positions(e, pos);
    TextRun run;
    collect_text(e, ctm, style, pos, run, layer);
    place_text(run, ctm, layer);
  }

  // Lays out and draws what the run holds, then empties it.
  void place_text(TextRun& run, const Affine& ctm, const std::string* layer) {
    while (!run.chars.empty() && run.chars.back().code == ' ') run.chars.pop_back();
    if (!run.chars.empty()) add_glyphs(svgtext::lay_out_text(run.chars), run, ctm, layer);
    run.chars.clear();
  }

  void add_glyphs(const svgtext::TextResult& r, const TextRun& run, const Affine& ctm, const std::string* layer) {
    missing_glyphs_ += r.missing;
    for (const auto& g : r.glyphs) {
      const Style& st = run.paints[g.paint];
      if (!st.visible || (st.fill.none && st.stroke.none)) continue;
      Style pen = st;  // text is drawn in its fill colour, or its stroke's when unfilled
      if (!pen.fill.none) pen.stroke = pen.fill;
      Color c;
      Layer& l = layer_for(pen, layer, c);
      for (const auto& stroke : g.strokes) {
        Polyline pl;
        pl.pts.reserve(stroke.size());
        for (const Vec2& p : stroke) {
          const Vec2 q = ctm.apply(p);
          check_point(q);
          if (++points_ > opt_.max_points)
            fail(element_, "makes the drawing more than " + std::to_string(opt_.max_points) + " points");
          pl.pts.push_back(q);
        }
        l.lines.push_back(std::move(pl));
      }
    }
  }

  // <textPath href startOffset>: the characters along the referenced path (its own
  // transform applies in the text's user space).
  void text_path(const tinyxml2::XMLElement* e, const Affine& ctm, const Style& style, const std::string* layer) {
    const tinyxml2::XMLElement* target = referenced(e);
    if (!target) return;
    Affine path_ctm = ctm;
    if (const char* t = target->Attribute("transform")) path_ctm = compose(target, ctm, parse_transform(target, t));
    std::vector<Vec2> path = user_space_outline(target, path_ctm, ctm);
    if (path.size() < 2) return;
    PositionLists pos;
    push_positions(e, pos);
    TextRun run;
    collect_text(e, ctm, style, pos, run, layer);
    double offset = 0;
    if (const char* so = e->Attribute("startOffset")) {
      std::string v = trim(so);
      double x;
      std::string unit;
      double length = 0;
      for (size_t k = 1; k < path.size(); ++k) length += std::hypot(path[k].x - path[k - 1].x, path[k].y - path[k - 1].y);
      if (!v.empty() && v.back() == '%' && split_number_unit(v.substr(0, v.size() - 1), x, unit) && unit.empty())
        offset = length * x / 100;
      else if (!parse_length(v.c_str(), 1.0 / kMmPerPx, offset))
        fail(e, "startOffset: bad value '" + v + "'");
    }
    while (!run.chars.empty() && run.chars.back().code == ' ') run.chars.pop_back();
    add_glyphs(svgtext::lay_out_on_path(run.chars, path, offset), run, ctm, layer);
  }

  // A shape's first subpath flattened in page mm through `shape_ctm`, brought back to the
  // user space of `user_ctm` (where text is laid out).
  std::vector<Vec2> user_space_outline(const tinyxml2::XMLElement* shape, const Affine& shape_ctm, const Affine& user_ctm) {
    std::vector<Polyline> saved_shape = std::move(shape_);
    std::vector<Vec2> saved_cur = std::move(cur_);
    shape_.clear();
    cur_.clear();
    build_shape(shape, local(shape->Name()), shape_ctm);
    flush_current();
    std::vector<Vec2> out;
    const double det = user_ctm.det();
    if (!shape_.empty() && std::fabs(det) > 1e-300) {
      const Affine& m = user_ctm;  // invert x' = a x + c y + e, y' = b x + d y + f
      for (const Vec2& p : shape_.front().pts) {
        const double px = p.x - m.e, py = p.y - m.f;
        out.push_back({(m.d * px - m.c * py) / det, (-m.b * px + m.a * py) / det});
      }
    }
    shape_ = std::move(saved_shape);
    cur_ = std::move(saved_cur);
    return out;
  }

  // Inkscape's flowed text (flowRoot): the paragraphs wrapped into the bounding box of the
  // first flowRegion's shape (exclusions are not subtracted).
  void flow_root(const tinyxml2::XMLElement* e, const Affine& ctm, const Style& style, const std::string* layer) {
    svgtext::require_fonts();
    Rect box;
    bool have_box = false;
    for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c && !have_box; c = c->NextSiblingElement()) {
      if (std::strcmp(local(c->Name()), "flowRegion") != 0) continue;
      for (const tinyxml2::XMLElement* sh = c->FirstChildElement(); sh && !have_box; sh = sh->NextSiblingElement()) {
        Affine sh_ctm = ctm;
        if (const char* t = sh->Attribute("transform")) sh_ctm = compose(sh, ctm, parse_transform(sh, t));
        const std::vector<Vec2> pts = user_space_outline(sh, sh_ctm, ctm);
        if (pts.size() < 3) continue;
        box = {pts[0].x, pts[0].y, pts[0].x, pts[0].y};
        for (const Vec2& p : pts) box = {std::min(box.x0, p.x), std::min(box.y0, p.y), std::max(box.x1, p.x), std::max(box.y1, p.y)};
        have_box = !box.empty();
      }
    }
    if (!have_box) return;
    PositionLists none;
    push_positions(e, none);
    TextRun run;
    collect_text(e, ctm, style, none, run, layer);
    if (!run.chars.empty()) add_glyphs(svgtext::lay_out_in_box(run.chars, box), run, ctm, layer);
  }

  // ---------- layers ----------
  Layer& layer_for(const Style& style, const std::string* label, Color& colour_out) {
    const Paint& paint = !style.stroke.none ? style.stroke : style.fill;
    colour_out = paint.none ? colors::black : paint.color;
    // Consecutive shapes nearly always share a layer: no key built, no lookup.
    if (last_layer_.valid && (label ? last_layer_.labelled && last_layer_.label == *label
                                    : !last_layer_.labelled && last_layer_.colour == colour_out))
      return drawing_.layers[last_layer_.index];
    std::string key = label ? "L:" + *label : "C:" + colour_out.hex();
    auto it = index_.find(key);
    if (it == index_.end()) {
      it = index_.emplace(key, LayerInfo{drawing_.layers.size()}).first;
      Layer l;
      if (label) {
        // "1 black" -> "black": a leading pen number is the AxiDraw convention
        std::string name = *label;
        size_t i = 0;
        while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i]))) ++i;
        if (i > 0 && i < name.size() && name[i] == ' ') {
          if (i <= 4) l.pen.number = std::stoi(name.substr(0, i));  // the pen, as AxiDraw reads it
          name = trim(name.substr(i + 1));
        }
        l.pen.name = name.empty() ? *label : name;
      } else {
        l.pen.name = colour_out.hex();
      }
      drawing_.layers.push_back(std::move(l));
    }
    LayerInfo& info = it->second;
    Layer& layer = drawing_.layers[info.index];
    if (!info.pen_set) {
      info.pen_set = true;
      layer.pen.color = colour_out;
      layer.pen.width_mm = style.stroke_width_mm > 0 ? style.stroke_width_mm : opt_.default_pen_width_mm;
    }
    last_layer_.valid = true;
    last_layer_.labelled = label != nullptr;
    if (label) last_layer_.label = *label;
    last_layer_.colour = colour_out;
    last_layer_.index = info.index;
    return layer;
  }

  // A shape's outline as lines (the stroke, or the edge of an unstroked fill), and, when
  // it is filled, its subpaths as the rings of an area (each closed, as SVG fills them) on
  // the layer of the fill colour, which the planner hatches.
  void add_shape(const Style& style, const std::string* label, bool fillable) {
    if (fillable && !style.fill.none && !style.fill.pattern) {
      Area area;
      area.rule = style.fill_rule;
      area.fill = style.fill.color;
      for (const auto& pl : shape_) {
        if (pl.pts.size() < 3) continue;
        Polyline ring = pl;
        if (!(ring.pts.front() == ring.pts.back())) ring.pts.push_back(ring.pts.front());
        area.rings.push_back(std::move(ring));
      }
      if (!area.rings.empty()) {
        Style fill_only = style;
        fill_only.stroke.none = true;
        Color c;
        layer_for(label ? style : fill_only, label, c).areas.push_back(std::move(area));
      }
    }
    Color c;
    Layer& layer = layer_for(style, label, c);
    for (auto& pl : shape_) layer.lines.push_back(std::move(pl));
    shape_.clear();
  }

  void round_shape(const tinyxml2::XMLElement* e, Vec2 c, double r_mm, const Style& style, const std::string* label) {
    element_ = e;
    check_point(c);
    if (!(r_mm <= kMaxCoordinateMm)) fail(e, "has a radius beyond 1000000 mm (or not a number)");
    const bool filled = !style.fill.none && !style.fill.pattern;
    const bool stroked = !style.stroke.none;
    if (filled && stroked && !label && !(style.fill.color == style.stroke.color)) {
      // Two pens, as it looks: the disc in the fill's, its outline in the stroke's.
      Style fill_only = style, outline_only = style;
      fill_only.stroke.none = true;
      outline_only.fill.none = true;
      round_shape(e, c, r_mm, fill_only, label);
      round_shape(e, c, r_mm, outline_only, label);
      return;
    }
    Color colour;
    Layer& layer = layer_for(style, label, colour);
    double pen = style.stroke_width_mm > 0 ? style.stroke_width_mm : opt_.default_pen_width_mm;
    if (filled && !stroked && 2 * r_mm <= pen * (1 + 1e-6) + 1e-9) {
      layer.dots.push_back({c, 2 * r_mm});
      return;
    }
    Circle circle;
    circle.c = c;
    circle.r = r_mm;
    circle.filled = filled;
    if (filled) circle.fill = style.fill.color;
    layer.circles.push_back(circle);
  }

  void finish_layers() {
    // drop layers that ended up empty (cannot happen today, kept for safety)
    std::erase_if(drawing_.layers, [](const Layer& l) { return l.primitive_count() == 0; });
  }

  const std::string& name_;
  const SvgReadOptions& opt_;
  Drawing drawing_;
  std::map<std::string, LayerInfo> index_;
  struct LastLayer {  // the layer layer_for gave last, its pen set
    bool valid = false, labelled = false;
    std::string label;
    Color colour;
    size_t index = 0;
  } last_layer_;
  std::map<std::string, const tinyxml2::XMLElement*> ids_;
  int use_depth_ = 0;
  size_t use_copies_ = 0, points_ = 0;               // work so far, against the options' caps
  const tinyxml2::XMLElement* element_ = nullptr;  // the element being drawn, for errors
  size_t missing_glyphs_ = 0;
  std::vector<Vec2> cur_;
  std::vector<Polyline> shape_;
};

// ---------- streaming: the document never whole in memory ----------
// Two passes of expat over the text. The first checks the XML and collects the ids that
// an href="#id" names. The second builds each element as tinyxml2 nodes for the Reader,
// walks an element and its subtree as soon as it ends, and frees it unless an href names
// something in it. Groups (g, svg, a) are never held whole: their children are walked one
// by one in the group's context, in document order as the tree walk does, so both ways
// draw the same (tests compare them on every SVG they read). Memory is then the drawing,
// the open groups and the referenced elements. A reference to an element not complete
// yet (a forward one, or one inside its target) needs the tree: reading starts again
// through it (NeedsTree); so does XML that expat refuses, for tinyxml2's own message (or
// its leniency).

struct NeedsTree {};

// The SVG's bytes, from a string in memory or read from a file in chunks.
struct Source {
  const std::string* text = nullptr;
  std::string path;

  // f(data, size, last) over the whole source, in chunks expat takes (an int's size).
  template <class F>
  void each_chunk(F&& f) const {
    constexpr size_t kChunk = 1 << 20;
    if (text) {
      size_t at = 0;
      do {
        const size_t n = std::min(kChunk, text->size() - at);
        if (!f(text->data() + at, n, at + n == text->size())) return;
        at += n;
      } while (at < text->size());
      return;
    }
    std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!file) throw UserError("cannot read " + path);
    std::vector<char> buf(kChunk);
    for (;;) {
      const size_t n = std::fread(buf.data(), 1, buf.size(), file.get());
      if (std::ferror(file.get())) throw UserError("cannot read " + path);
      const bool last = n < buf.size() && std::feof(file.get());
      if (!f(buf.data(), n, last) || last) return;
    }
  }

  // Bytes in the source (0 when its size cannot be told: read as a small one).
  size_t size() const {
    if (text) return text->size();
    std::error_code ec;
    const auto n = std::filesystem::file_size(path, ec);
    return ec ? 0 : static_cast<size_t>(n);
  }

  std::string whole() const {
    if (text) return *text;
    std::string out;
    each_chunk([&](const char* d, size_t n, bool) {
      out.append(d, n);
      return true;
    });
    return out;
  }
};

// One expat parser; an exception from a handler is kept and rethrown once expat has
// returned (it must not unwind through expat's C frames).
class Expat {
 public:
  Expat() : p_(XML_ParserCreate(nullptr)) {
    if (!p_) throw std::bad_alloc();
  }
  ~Expat() { XML_ParserFree(p_); }
  Expat(const Expat&) = delete;
  Expat& operator=(const Expat&) = delete;
  XML_Parser get() const { return p_; }

  template <class F>
  void guard(F&& f) {
    if (error_) return;
    try {
      f();
    } catch (...) {
      error_ = std::current_exception();
      XML_StopParser(p_, XML_FALSE);
    }
  }
  // Feeds the whole source; false when the XML is malformed.
  bool parse(const Source& src) {
    bool ok = true;
    src.each_chunk([&](const char* d, size_t n, bool last) {
      ok = XML_Parse(p_, d, static_cast<int>(n), last) == XML_STATUS_OK;
      return ok;
    });
    if (error_) std::rethrow_exception(error_);
    return ok;
  }

 private:
  XML_Parser p_;
  std::exception_ptr error_;
};

const char* href_of(const XML_Char** attrs, int which) {
  int seen = 0;
  for (int i = 0; attrs[i]; i += 2)
    if ((std::strcmp(attrs[i], "href") == 0 || std::strcmp(attrs[i], "xlink:href") == 0) && attrs[i + 1][0] == '#' &&
        seen++ == which)
      return attrs[i + 1] + 1;
  return nullptr;
}

// Pass 1: the ids some href="#id" names; nullopt when the XML is malformed. A text with
// no "href" at all names none: a scan for it (memory speed) replaces the pass.
std::optional<std::unordered_set<std::string>> referenced_ids(const Source& src) {
  bool any = false;
  std::string seam;  // the previous chunk's last 3 bytes, then this one's first 3: a match across chunks
  src.each_chunk([&](const char* d, size_t n, bool) {
    const std::string_view view(d, n);
    seam.append(view.substr(0, 3));
    any = seam.find("href") != std::string::npos || view.find("href") != std::string_view::npos;
    seam.assign(view.substr(n - std::min<size_t>(n, 3)));
    return !any;
  });
  if (!any) return std::unordered_set<std::string>{};
  Expat x;
  std::unordered_set<std::string> ids;
  XML_SetUserData(x.get(), &ids);
  XML_SetStartElementHandler(x.get(), [](void* u, const XML_Char*, const XML_Char** attrs) {
    auto& ids = *static_cast<std::unordered_set<std::string>*>(u);
    for (int k = 0; const char* id = href_of(attrs, k); ++k) ids.insert(id);
  });
  if (!x.parse(src)) return std::nullopt;
  return ids;
}

// expat's callbacks as data, for replaying on another thread: element starts (name and
// attribute strings), ends, character data and the markup that splits it.
struct XmlEvents {
  enum Kind : uint8_t { start, end, chars, markup };
  struct Event {
    Kind kind;
    int line;        // start: the element's line
    uint32_t first;  // start: its name's index in offsets; chars: offset in text
    uint32_t count;  // start: 1 + 2 x attributes; chars: bytes
  };
  std::string text;               // names and values, each NUL-terminated; character data
  std::vector<uint32_t> offsets;  // where each string of a start begins in text
  std::vector<Event> events;
  bool full() const { return events.size() >= 16384 || text.size() >= (size_t{1} << 20); }
  uint32_t add(const char* s, size_t n, bool terminate) {
    const uint32_t at = static_cast<uint32_t>(text.size());
    text.append(s, n);
    if (terminate) text.push_back('\0');
    return at;
  }
};

// Runs expat over a source on the calling thread, handing its events over in batches
// (a few ahead at most: memory stays bounded) to a reader that takes them with next().
class Tokenizer {
 public:
  void run(const Source& src) {
    Expat x;
    x_ = &x;
    XML_SetUserData(x.get(), this);
    XML_SetElementHandler(
        x.get(),
        [](void* u, const XML_Char* name, const XML_Char** attrs) {
          auto* t = static_cast<Tokenizer*>(u);
          t->x_->guard([&] { t->start(name, attrs); });
        },
        [](void* u, const XML_Char*) {
          auto* t = static_cast<Tokenizer*>(u);
          t->x_->guard([&] { t->record({XmlEvents::end, 0, 0, 0}); });
        });
    XML_SetCharacterDataHandler(x.get(), [](void* u, const XML_Char* d, int n) {
      auto* t = static_cast<Tokenizer*>(u);
      t->x_->guard([&] { t->chars(d, static_cast<size_t>(n)); });
    });
    XML_SetCommentHandler(x.get(), [](void* u, const XML_Char*) {
      auto* t = static_cast<Tokenizer*>(u);
      t->x_->guard([&] { t->record({XmlEvents::markup, 0, 0, 0}); });
    });
    XML_SetProcessingInstructionHandler(x.get(), [](void* u, const XML_Char*, const XML_Char*) {
      auto* t = static_cast<Tokenizer*>(u);
      t->x_->guard([&] { t->record({XmlEvents::markup, 0, 0, 0}); });
    });
    bool ok = false;
    std::exception_ptr error;
    try {
      ok = x.parse(src);
    } catch (...) {
      error = std::current_exception();  // a read error, or the reader gave up (abandon)
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (!filling_.events.empty()) queue_.push_back(std::move(filling_));
    ok_ = ok;
    error_ = error;
    done_ = true;
    changed_.notify_all();
  }

  // The next batch in order; false once all are taken. Rethrows what stopped the tokenising.
  bool next(XmlEvents& out) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return done_ || !queue_.empty(); });
    if (queue_.empty()) {
      if (error_) std::rethrow_exception(error_);
      return false;
    }
    out = std::move(queue_.front());
    queue_.pop_front();
    changed_.notify_all();
    return true;
  }
  // The reader stopped (an error of its own): the tokenising stops at its next event.
  void abandon() {
    std::lock_guard<std::mutex> lock(mutex_);
    abandoned_ = true;
    changed_.notify_all();
  }
  bool result() const { return ok_; }  // after run: false when the XML is malformed

 private:
  struct Abandoned {};

  void start(const XML_Char* name, const XML_Char** attrs) {
    XmlEvents& b = filling_;
    uint32_t count = 1;
    const uint32_t first = static_cast<uint32_t>(b.offsets.size());
    b.offsets.push_back(b.add(name, std::strlen(name), true));
    for (int i = 0; attrs[i]; ++i, ++count) b.offsets.push_back(b.add(attrs[i], std::strlen(attrs[i]), true));
    record({XmlEvents::start, static_cast<int>(XML_GetCurrentLineNumber(x_->get())), first, count});
  }
  void chars(const char* d, size_t n) {
    XmlEvents& b = filling_;
    // Runs of character data are one event, as the reader appends them all the same.
    if (!b.events.empty() && b.events.back().kind == XmlEvents::chars && b.events.back().first + b.events.back().count == b.text.size()) {
      b.add(d, n, false);
      b.events.back().count += static_cast<uint32_t>(n);
      return;
    }
    const uint32_t at = b.add(d, n, false);
    record({XmlEvents::chars, 0, at, static_cast<uint32_t>(n)});
  }
  void record(const XmlEvents::Event& e) {
    filling_.events.push_back(e);
    if (!filling_.full()) return;
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return abandoned_ || queue_.size() < 4; });
    if (abandoned_) throw Abandoned{};
    queue_.push_back(std::move(filling_));
    filling_ = XmlEvents{};
    changed_.notify_all();
  }

  Expat* x_ = nullptr;
  XmlEvents filling_;
  std::deque<XmlEvents> queue_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool done_ = false, ok_ = false, abandoned_ = false;
  std::exception_ptr error_;
};

// Pass 2 (see above).
class StreamReader {
 public:
  StreamReader(Reader& reader, std::unordered_set<std::string> targets)
      : r_(reader), targets_(std::move(targets)), opt_tokenize_apart_(reader.opt_.tokenize_apart_from_bytes) {}

  Drawing run(const Source& src) {
    if (src.size() >= opt_tokenize_apart_ && (thread_count() >= 2 || opt_tokenize_apart_ == 0)) {
      if (!run_apart(src)) throw NeedsTree{};  // malformed XML: tinyxml2 reads it or says why
    } else {
      if (!run_here(src)) throw NeedsTree{};
    }
    if (!root_drawn_) return std::move(r_.drawing_);
    return r_.finish();
  }

 private:
  // expat's callbacks drawing as they come; false when the XML is malformed.
  bool run_here(const Source& src) {
    Expat x;
    XML_SetUserData(x.get(), this);
    XML_SetElementHandler(
        x.get(),
        [](void* u, const XML_Char* name, const XML_Char** attrs) {
          auto* s = static_cast<StreamReader*>(u);
          s->x_->guard([&] { s->start(name, attrs, static_cast<int>(XML_GetCurrentLineNumber(s->x_->get()))); });
        },
        [](void* u, const XML_Char*) {
          auto* s = static_cast<StreamReader*>(u);
          s->x_->guard([&] { s->end(); });
        });
    XML_SetCharacterDataHandler(x.get(), [](void* u, const XML_Char* d, int n) {
      auto* s = static_cast<StreamReader*>(u);
      if (s->held_top_ != kNone) s->x_->guard([&] { s->text_.append(d, static_cast<size_t>(n)); });
    });
    // Markup between characters splits them into text nodes, as tinyxml2 does.
    XML_SetCommentHandler(x.get(), [](void* u, const XML_Char*) {
      auto* s = static_cast<StreamReader*>(u);
      s->x_->guard([&] { s->flush_text(); });
    });
    XML_SetProcessingInstructionHandler(x.get(), [](void* u, const XML_Char*, const XML_Char*) {
      auto* s = static_cast<StreamReader*>(u);
      s->x_->guard([&] { s->flush_text(); });
    });
    x_ = &x;
    return x.parse(src);
  }

  // expat on a thread of its own, its callbacks recorded in batches (XmlEvents) that this
  // thread replays in order through the same start/end/text calls: the same drawing, with
  // the tokenising (a third of the reading) on the other core. False when malformed.
  bool run_apart(const Source& src) {
    Tokenizer tok;
    std::thread worker([&] { tok.run(src); });
    try {
      std::vector<const char*> attrs;
      for (XmlEvents batch; tok.next(batch);) {
        for (const XmlEvents::Event& e : batch.events) {
          switch (e.kind) {
            case XmlEvents::start: {
              attrs.clear();
              for (uint32_t k = 1; k < e.count; ++k) attrs.push_back(batch.text.data() + batch.offsets[e.first + k]);
              attrs.push_back(nullptr);
              start(batch.text.data() + batch.offsets[e.first], attrs.data(), e.line);
              break;
            }
            case XmlEvents::end: end(); break;
            case XmlEvents::chars:
              if (held_top_ != kNone) text_.append(batch.text, e.first, e.count);
              break;
            case XmlEvents::markup: flush_text(); break;
          }
        }
      }
    } catch (...) {
      tok.abandon();
      worker.join();
      throw;
    }
    worker.join();
    return tok.result();
  }

  static constexpr size_t kNone = static_cast<size_t>(-1);

  struct Frame {
    explicit Frame(tinyxml2::XMLElement* e, bool is_group = false) : el(e), group(is_group) {}
    tinyxml2::XMLElement* el;
    bool group = false;  // a g, svg or a whose children are walked one by one as they end
    bool drawn = false;  // (group) its children are drawn
    std::unique_ptr<Reader::Context> ctx;  // (group, drawn) what its children inherit
    bool keep = false;   // (top of a held subtree) an href names something in it
  };

  void start(const XML_Char* name, const XML_Char** attrs, int line) {
    flush_text();
    tinyxml2::XMLElement* el = doc_.NewElement(name);
    el->SetUserData(reinterpret_cast<void*>(static_cast<intptr_t>(line)));
    const char* id = nullptr;
    for (int i = 0; attrs[i]; i += 2) {
      el->SetAttribute(attrs[i], attrs[i + 1]);
      if (std::strcmp(attrs[i], "id") == 0) id = attrs[i + 1];
    }
    // What an href names must be complete by now, or the tree walk is needed.
    for (int k = 0; const char* ref = href_of(attrs, k); ++k) {
      auto it = r_.ids_.find(ref);
      if (it == r_.ids_.end() || open_targets_.count(it->second)) throw NeedsTree{};
    }
    const bool target = id && targets_.count(id);
    if (target) {
      r_.ids_.emplace(id, el);
      open_targets_.insert(el);
    }
    if (stack_.empty()) {  // the root
      doc_.InsertEndChild(el);
      Frame f(el, true);
      f.ctx = std::make_unique<Reader::Context>();
      f.drawn = root_drawn_ = r_.begin(el, *f.ctx);
      stack_.push_back(std::move(f));
      return;
    }
    Frame& parent = stack_.back();
    parent.el->InsertEndChild(el);
    if (held_top_ != kNone) {  // inside a held subtree
      if (target) stack_[held_top_].keep = true;
      stack_.push_back(Frame(el));
      return;
    }
    if (Reader::is_container(Reader::local(name)) && !target) {
      Frame f(el, true);
      if (parent.drawn) {
        f.ctx = std::make_unique<Reader::Context>();
        f.drawn = r_.enter(el, *parent.ctx, *f.ctx);
      }
      stack_.push_back(std::move(f));
      return;
    }
    held_top_ = stack_.size();
    Frame f(el);
    f.keep = target;
    stack_.push_back(std::move(f));
  }

  void end() {
    flush_text();
    Frame f = std::move(stack_.back());
    stack_.pop_back();
    if (!open_targets_.empty()) open_targets_.erase(f.el);
    if (stack_.empty()) return;  // the root
    Frame& parent = stack_.back();
    if (f.group) {
      if (!f.el->FirstChild()) forget(parent, f.el);
      return;
    }
    if (held_top_ != stack_.size()) return;  // inside a held subtree
    held_top_ = kNone;
    if (parent.drawn) r_.walk(f.el, parent.ctx->ctm, parent.ctx->style, parent.ctx->layer);
    if (!f.keep) forget(parent, f.el);
  }

  void forget(Frame& parent, tinyxml2::XMLElement* el) {
    parent.el->DeleteChild(el);
    r_.element_ = nullptr;  // it may have been this one
  }

  // Characters become a text node of the element they are in, unless they are only white
  // space between markup (tinyxml2 drops those too).
  void flush_text() {
    if (text_.empty()) return;
    if (text_.find_first_not_of(" \t\n\v\f\r") != std::string::npos)
      stack_.back().el->InsertEndChild(doc_.NewText(text_.c_str()));
    text_.clear();
  }

  Reader& r_;
  std::unordered_set<std::string> targets_;
  tinyxml2::XMLDocument doc_;
  std::vector<Frame> stack_;
  std::unordered_set<const tinyxml2::XMLElement*> open_targets_;
  size_t held_top_ = kNone;  // index in stack_ of the held subtree's top
  std::string text_;
  bool root_drawn_ = false;
  Expat* x_ = nullptr;
  size_t opt_tokenize_apart_;
};

Drawing read_tree(const std::string& text, const std::string& name, const SvgReadOptions& opt,
                  SvgReadReport* report) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
    std::string msg = doc.ErrorStr() ? doc.ErrorStr() : "XML error";
    throw UserError(name + " line " + std::to_string(doc.ErrorLineNum()) + ": malformed XML: " + msg);
  }
  Reader reader(name, opt);
  Drawing d = reader.run(doc);
  if (report) report->missing_glyphs = reader.missing_glyphs();
  return d;
}

Drawing read_source(const Source& src, const std::string& name, const SvgReadOptions& opt,
                    SvgReadReport* report) {
  require_positive("SVG flattening tolerance", opt.tolerance_mm);
  require_positive("default pen width", opt.default_pen_width_mm);
  if (opt.stream) {
    if (auto targets = referenced_ids(src)) {
      try {
        Reader reader(name, opt);
        StreamReader stream(reader, std::move(*targets));
        Drawing d = stream.run(src);
        if (report) {
          report->missing_glyphs = reader.missing_glyphs();
          report->streamed = true;
        }
        return d;
      } catch (const NeedsTree&) {
      }
    }
  }
  return read_tree(src.whole(), name, opt, report);
}

}  // namespace

Drawing parse_svg(const std::string& text, const std::string& name, const SvgReadOptions& opt, SvgReadReport* report) {
  Source src;
  src.text = &text;
  return read_source(src, name, opt, report);
}

Drawing read_svg(const std::string& path, const SvgReadOptions& opt, SvgReadReport* report) {
  Source src;
  src.path = path;
  return read_source(src, path, opt, report);
}

}  // namespace stipplot
