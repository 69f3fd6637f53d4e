#include "svg/svg_reader.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>

#include "geometry/affine.hpp"
#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kMmPerPx = 25.4 / 96.0;

struct Paint {
  bool none = false;
  Color color = colors::black;
};

struct Style {
  Paint stroke{true, colors::black};  // SVG default: no stroke
  Paint fill{false, colors::black};   // SVG default: black fill
  double stroke_width = 1;            // user units of the element that set it
  double stroke_width_mm = -1;        // resolved with the transform in effect where set; -1 unset
  bool visible = true;
};

class Reader {
 public:
  Reader(const std::string& name, const SvgReadOptions& opt) : name_(name), opt_(opt) {}

  Drawing run(const tinyxml2::XMLDocument& doc) {
    const tinyxml2::XMLElement* root = doc.RootElement();
    if (!root || std::strcmp(local(root->Name()), "svg") != 0)
      throw UserError(name_ + ": not an SVG file (the root element is not <svg>)");
    Affine ctm = root_transform(root);
    Style style;
    style.stroke_width_mm = -1;
    apply_style(root, style, ctm);
    if (display_none(root)) return drawing_;
    walk_children(root, ctm, style, nullptr);
    finish_layers();
    return drawing_;
  }

 private:
  struct LayerInfo {
    size_t index;
    bool pen_set = false;
  };

  // ---------- errors and attributes ----------
  [[noreturn]] void fail(const tinyxml2::XMLElement* e, const std::string& what) const {
    throw UserError(name_ + " line " + std::to_string(e->GetLineNum()) + ": <" + e->Name() + "> " + what);
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
    auto paint = [&](const char* prop, Paint& p) {
      auto v = property(e, prop);
      if (!v || *v == "inherit" || v->empty()) return;
      if (*v == "none" || *v == "transparent") {
        p.none = true;
        return;
      }
      p.none = false;
      Color c;
      if (*v == "currentColor" || v->rfind("url(", 0) == 0) c = colors::black;  // gradients: plot in black
      else if (!Color::try_parse(*v, c)) fail(e, std::string(prop) + ": not a colour: '" + *v + "'");
      p.color = c;
    };
    paint("stroke", s.stroke);
    paint("fill", s.fill);
    if (auto w = property(e, "stroke-width"); w && *w != "inherit") {
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
    if (auto v = property(e, "visibility")) {
      if (*v == "hidden" || *v == "collapse") s.visible = false;
      else if (*v == "visible") s.visible = true;
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
        rad = v[0] * kPi / 180;
        Affine r{std::cos(rad), std::sin(rad), -std::sin(rad), std::cos(rad), 0, 0};
        if (v.size() == 3) {
          Affine to{1, 0, 0, 1, v[1], v[2]}, back{1, 0, 0, 1, -v[1], -v[2]};
          m = to * r * back;
        } else {
          m = r;
        }
      } else if (fn == "skewX") {
        nargs({1});
        m.c = std::tan(v[0] * kPi / 180);
      } else if (fn == "skewY") {
        nargs({1});
        m.b = std::tan(v[0] * kPi / 180);
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

  void walk(const tinyxml2::XMLElement* e, Affine ctm, Style style, const std::string* layer) {
    const char* tag = local(e->Name());
    static const char* kSkip[] = {"defs", "title", "desc", "metadata", "symbol", "clipPath", "mask", "pattern",
                                  "marker", "style", "script", "namedview", "linearGradient", "radialGradient",
                                  "filter", "text", "image", "foreignObject", "switch"};
    for (const char* s : kSkip)
      if (std::strcmp(tag, s) == 0) return;
    if (display_none(e)) return;
    if (const char* t = e->Attribute("transform")) ctm = ctm * parse_transform(e, t);
    apply_style(e, style, ctm);

    if (std::strcmp(tag, "g") == 0 || std::strcmp(tag, "svg") == 0 || std::strcmp(tag, "a") == 0) {
      std::string label_storage;
      const char* mode = e->Attribute("inkscape:groupmode");
      if (!layer && mode && std::strcmp(mode, "layer") == 0) {
        const char* label = e->Attribute("inkscape:label");
        if (!label) label = e->Attribute("id");
        label_storage = label ? trim(label) : "layer";
        if (!label_storage.empty() && label_storage[0] == '%') return;  // not for plotting
        layer = &label_storage;
      }
      if (std::strcmp(tag, "svg") == 0 && e != e->GetDocument()->RootElement()) {
        ctm = ctm * Affine{1, 0, 0, 1, length_attr(e, "x", 0), length_attr(e, "y", 0)};
      }
      walk_children(e, ctm, style, layer);
      return;
    }
    if (std::strcmp(tag, "use") == 0) {
      use(e, ctm, style, layer);
      return;
    }
    if (!style.visible) return;

    shape_ = {};
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
    } else if (std::strcmp(tag, "circle") == 0 || std::strcmp(tag, "ellipse") == 0) {
      if (circle_or_ellipse(e, tag[0] == 'c', ctm, style, layer)) return;
    } else {
      return;  // unknown elements (use, text...) draw nothing here
    }
    flush_current();
    if (!shape_.empty()) add_lines(style, layer);
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
    Affine t = ctm * Affine{1, 0, 0, 1, length_attr(e, "x", 0), length_attr(e, "y", 0)};
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
    cur_.push_back(ctm.apply(user));
  }
  void line(Vec2 user, const Affine& ctm) { push(ctm.apply(user)); }
  void push(Vec2 p) {
    if (cur_.empty() || !(cur_.back() == p)) cur_.push_back(p);
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
    int n = static_cast<int>(std::ceil(std::fabs(dt) / step));
    n = std::clamp(n, 1, 100000);
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
          if (cur_.empty()) cur_.push_back(ctm.apply(pos));
          arc(pos, rx, ry, rot, large, sweep, p, ctm);
          pos = p;
          break;
        }
        case 'Z':
          close();
          pos = start;
          // a drawing command after Z starts a new subpath at the start point
          flush_current();
          cur_.push_back(ctm.apply(pos));
          break;
        default:
          bad(std::string("unknown path command '") + cmd + "'");
      }
      prev = cmd;
    }
    flush_current();
  }

  void curve(Vec2 p0, Vec2 c1, Vec2 c2, Vec2 p, const Affine& ctm) {
    if (cur_.empty()) cur_.push_back(ctm.apply(p0));
    cubic(ctm.apply(p0), ctm.apply(c1), ctm.apply(c2), ctm.apply(p));
  }
  void quad(Vec2 p0, Vec2 q, Vec2 p, const Affine& ctm) {
    // degree elevation: a quadratic is the cubic with controls 2/3 of the way to q
    Vec2 c1{p0.x + 2.0 / 3 * (q.x - p0.x), p0.y + 2.0 / 3 * (q.y - p0.y)};
    Vec2 c2{p.x + 2.0 / 3 * (q.x - p.x), p.y + 2.0 / 3 * (q.y - p.y)};
    curve(p0, c1, c2, p, ctm);
  }

  // ---------- layers ----------
  Layer& layer_for(const Style& style, const std::string* label, Color& colour_out) {
    const Paint& paint = !style.stroke.none ? style.stroke : style.fill;
    colour_out = paint.none ? colors::black : paint.color;
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
    return layer;
  }

  void add_lines(const Style& style, const std::string* label) {
    Color c;
    Layer& layer = layer_for(style, label, c);
    for (auto& pl : shape_) layer.lines.push_back(std::move(pl));
    shape_.clear();
  }

  void round_shape(const tinyxml2::XMLElement*, Vec2 c, double r_mm, const Style& style, const std::string* label) {
    Color colour;
    Layer& layer = layer_for(style, label, colour);
    const bool filled = !style.fill.none;
    const bool stroked = !style.stroke.none;
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
  std::map<std::string, const tinyxml2::XMLElement*> ids_;
  int use_depth_ = 0;
  std::vector<Vec2> cur_;
  std::vector<Polyline> shape_;
};

}  // namespace

Drawing parse_svg(const std::string& text, const std::string& name, const SvgReadOptions& opt) {
  require_positive("SVG flattening tolerance", opt.tolerance_mm);
  require_positive("default pen width", opt.default_pen_width_mm);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
    std::string msg = doc.ErrorStr() ? doc.ErrorStr() : "XML error";
    throw UserError(name + " line " + std::to_string(doc.ErrorLineNum()) + ": malformed XML: " + msg);
  }
  return Reader(name, opt).run(doc);
}

Drawing read_svg(const std::string& path, const SvgReadOptions& opt) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError("cannot read " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  if (!in.good() && !in.eof()) throw UserError("cannot read " + path);
  return parse_svg(ss.str(), path, opt);
}

}  // namespace stipplot
