#include "methods/sketch/sketch.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "eval/bounded_blur.hpp"
#include "methods/palette.hpp"
#include "methods/sketch/redistribution.hpp"
#include "util/error.hpp"
#include "util/rng.hpp"

namespace stipplot::sketch {

ColorSpace parse_color_space(const std::string& name) {
  if (name == "rgb") return ColorSpace::Rgb;
  if (name == "hsi") return ColorSpace::Hsi;
  throw UserError("--space: unknown colour space '" + name + "' (use rgb or hsi)");
}

const char* to_string(ColorSpace s) {
  switch (s) {
    case ColorSpace::Rgb: return "rgb";
    case ColorSpace::Hsi: return "hsi";
    case ColorSpace::Pens: return "pens";
  }
  return "?";
}

Lighten parse_lighten(const std::string& name) {
  if (name == "auto") return Lighten::Auto;
  if (name == "on") return Lighten::On;
  if (name == "off") return Lighten::Off;
  throw UserError("--lighten: expected auto, on or off, got '" + name + "'");
}

HsiBlack parse_hsi_black(const std::string& name) {
  if (name == "paper") return HsiBlack::Paper;
  if (name == "chroma") return HsiBlack::Chroma;
  throw UserError("--hsi-black: expected paper or chroma, got '" + name + "'");
}

PreviewStyle parse_preview_style(const std::string& name) {
  if (name == "paper") return PreviewStyle::Paper;
  if (name == "plot") return PreviewStyle::Plot;
  throw UserError("--preview-style: expected paper or plot, got '" + name + "'");
}

void SketchParams::validate() const {
  if (space == ColorSpace::Pens && pens.empty()) throw UserError("--pens: the palette has no pens");
  require_range("--reach", reach, 0, std::sqrt(3.0));
  require_nonnegative("--cell", cell.value);
  require_range("--mark", mark_mm, 0.01, 100);
  require_range("--edge-length", edge_mm, 0, 100);
  require_range("--edge-low", edge_low, 0, 1);
  require_range("--edge-high", edge_high, 0, 1);
  if (!(edge_high > edge_low)) throw UserError("--edge-high must be greater than --edge-low");
  if (max_passes < 1 || max_passes > 10) throw UserError("--passes must be in [1, 10]");
  require_range("--hatch", hatch_deg, -360, 360);
}

double SketchParams::auto_cell_mm(const std::vector<Pen>& pen_set) const {
  double w = 0;
  for (const auto& p : pen_set) w += p.width_mm;
  w = pen_set.empty() ? 0.3 : w / pen_set.size();
  return std::max(0.05, std::sqrt(mark_mm * w));
}

size_t SketchResult::plotted_strokes() const {
  size_t n = 0;
  for (const auto& p : pens)
    for (const auto& s : p.strokes) n += s.plotted;
  return n;
}

std::vector<Pen> builtin_pens(ColorSpace s, double width) {
  auto pen = [&](const char* name, uint8_t r, uint8_t g, uint8_t b) { return Pen{name, Color{r, g, b}, width}; };
  if (s == ColorSpace::Rgb)
    return {pen("red", 255, 0, 0),     pen("green", 0, 255, 0),  pen("blue", 0, 0, 255),
            pen("yellow", 255, 255, 0), pen("magenta", 255, 0, 255), pen("cyan", 0, 255, 255),
            pen("black", 0, 0, 0),     pen("grey", 128, 128, 128)};
  if (s == ColorSpace::Hsi)
    return {pen("red", 255, 0, 0),  pen("yellow", 255, 255, 0), pen("green", 0, 255, 0), pen("cyan", 0, 255, 255),
            pen("blue", 0, 0, 255), pen("magenta", 255, 0, 255), pen("black", 0, 0, 0)};
  return {};
}

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Rgb01 {
  double r, g, b;
};
Rgb01 to01(Color c) { return {c.r / 255.0, c.g / 255.0, c.b / 255.0}; }
double luma01(double r, double g, double b) { return 0.299 * r + 0.587 * g + 0.114 * b; }

// HSI hue in [0, 2pi) and saturation; hue < 0 when undefined (grey).
void hsi(double r, double g, double b, double& hue, double& sat) {
  const double sum = r + g + b;
  const double mn = std::min({r, g, b});
  sat = sum > 0 ? 1.0 - 3.0 * mn / sum : 0.0;
  const double num = 0.5 * ((r - g) + (r - b));
  const double den = std::sqrt((r - g) * (r - g) + (r - b) * (g - b));
  if (den < 1e-9) {
    hue = -1;
    return;
  }
  double th = std::acos(std::clamp(num / den, -1.0, 1.0));
  hue = b > g ? 2 * kPi - th : th;
}

double hue_of_pen(Color c) {
  double h, s;
  const Rgb01 p = to01(c);
  hsi(p.r, p.g, p.b, h, s);
  return h;
}

// The RGB reach of each pen: the paper's d for its built-in pens; for a user palette the
// distance to the nearest other pen, capped at sqrt(3)/2 (or the user's --reach).
std::vector<double> rgb_reach(const std::vector<Pen>& pens, const SketchParams& p) {
  const double cap = std::sqrt(3.0) / 2;
  std::vector<double> d(pens.size(), cap);
  if (p.space == ColorSpace::Rgb) {
    for (size_t i = 0; i < pens.size(); ++i)
      if (pens[i].name == "grey") d[i] = 0.15;
    return d;
  }
  for (size_t i = 0; i < pens.size(); ++i) {
    if (p.reach > 0) {
      d[i] = p.reach;
      continue;
    }
    const Rgb01 a = to01(pens[i].color);
    for (size_t j = 0; j < pens.size(); ++j) {
      if (j == i) continue;
      const Rgb01 b = to01(pens[j].color);
      const double dist = std::sqrt((a.r - b.r) * (a.r - b.r) + (a.g - b.g) * (a.g - b.g) + (a.b - b.b) * (a.b - b.b));
      if (dist > 0) d[i] = std::min(d[i], dist);  // identical colours under two names: keep the cap
    }
  }
  return d;
}

cv::Mat as_mat(const Image& im) {
  return cv::Mat(im.height, im.width, CV_8UC3, const_cast<uint8_t*>(im.rgb.data()));
}

Image resize_to(const Image& im, int w, int h) {
  if (im.width == w && im.height == h) return im;
  Image out;
  out.width = w;
  out.height = h;
  out.rgb.resize(out.pixels() * 3);
  cv::Mat dst(h, w, CV_8UC3, out.rgb.data());
  const bool shrink = w <= im.width && h <= im.height;
  cv::resize(as_mat(im), dst, cv::Size(w, h), 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out;
}

// Thinning for the plot: the share of a pen's marks to keep in a cell so that its ink
// covers (1 - t) of what it would cover unthinned. With marks falling independently at
// lambda = -ln(1 - p) per cell (one mark's ink = one cell's area, see auto_cell_mm), the
// covered share is 1 - exp(-lambda k) for a kept share k, so
//   k = -ln(1 - (1 - t) p) / -ln(1 - p),
// which is 1 - t for small p ("in proportion") and much less where marks pile up.
double keep_share(double p, double t) {
  p = std::clamp(p, 0.0, max_probability());
  t = std::clamp(t, 0.0, 1.0);
  if (p <= 1e-12) return 1 - t;
  return std::log1p(-(1 - t) * p) / std::log1p(-p);
}

double smoothstep(double lo, double hi, double v) {
  const double t = std::clamp((v - lo) / (hi - lo), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

}  // namespace

std::vector<std::vector<float>> pen_probabilities(const Image& grid, const SketchParams& params,
                                                  const std::vector<Pen>& pens) {
  const size_t n = grid.pixels();
  std::vector<std::vector<float>> p(pens.size(), std::vector<float>(n, 0.0f));
  if (params.space == ColorSpace::Hsi) {
    const double r = kPi / 3;
    std::vector<double> pen_hue(pens.size());
    for (size_t c = 0; c < pens.size(); ++c) pen_hue[c] = pens[c].name == "black" ? -1 : hue_of_pen(pens[c].color);
    const bool chroma = params.hsi_black == HsiBlack::Chroma;
    for (size_t i = 0; i < n; ++i) {
      const double R = grid.rgb[3 * i] / 255.0, G = grid.rgb[3 * i + 1] / 255.0, B = grid.rgb[3 * i + 2] / 255.0;
      double hue, sat;
      hsi(R, G, B, hue, sat);
      const double black = chroma ? std::exp(-5.0 * (std::max({R, G, B}) - std::min({R, G, B}))) : std::exp(-5.0 * sat);
      const double hue_scale = chroma ? 1.0 - black : 1.0;
      for (size_t c = 0; c < pens.size(); ++c) {
        if (pen_hue[c] < 0) {
          p[c][i] = static_cast<float>(black);
        } else if (hue >= 0) {
          double dth = std::abs(hue - pen_hue[c]);
          dth = std::min(dth, 2 * kPi - dth);
          p[c][i] = static_cast<float>(hue_scale * std::max(0.0, (r - dth) / r));
        }
      }
    }
    return p;
  }
  const std::vector<double> d = rgb_reach(pens, params);
  for (size_t c = 0; c < pens.size(); ++c) {
    const Rgb01 pc = to01(pens[c].color);
    const double inv = 1.0 / d[c];
    float* out = p[c].data();
    for (size_t i = 0; i < n; ++i) {
      const double dr = grid.rgb[3 * i] / 255.0 - pc.r, dg = grid.rgb[3 * i + 1] / 255.0 - pc.g,
                   db = grid.rgb[3 * i + 2] / 255.0 - pc.b;
      const double D = std::sqrt(dr * dr + dg * dg + db * db);
      out[i] = static_cast<float>(std::max(0.0, (d[c] - D) * inv));
    }
  }
  return p;
}

EdgeField edge_field(const Image& grid) {
  EdgeField f;
  f.w = grid.width;
  f.h = grid.height;
  const size_t n = grid.pixels();
  cv::Mat luma(grid.height, grid.width, CV_32F);
  for (size_t i = 0; i < n; ++i)
    luma.ptr<float>()[i] = static_cast<float>(luma01(grid.rgb[3 * i], grid.rgb[3 * i + 1], grid.rgb[3 * i + 2]) / 255.0);
  cv::Mat gx, gy;
  // Sobel / 8: luma change per cell.
  cv::Sobel(luma, gx, CV_32F, 1, 0, 3, 1.0 / 8, 0, cv::BORDER_REPLICATE);
  cv::Sobel(luma, gy, CV_32F, 0, 1, 3, 1.0 / 8, 0, cv::BORDER_REPLICATE);
  cv::Mat jxx = gx.mul(gx), jxy = gx.mul(gy), jyy = gy.mul(gy);
  // Smoothing the structure tensor (not the gradient) keeps opposite gradients on the two
  // sides of a thin line from cancelling, and steadies the direction in texture.
  for (cv::Mat* m : {&jxx, &jxy, &jyy}) gaussian_blur_rows(*m, *m, 1.0, cv::BORDER_REPLICATE);
  f.tx.resize(n);
  f.ty.resize(n);
  f.strength.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double a = jxx.ptr<float>()[i], b = jxy.ptr<float>()[i], c = jyy.ptr<float>()[i];
    const double lambda1 = 0.5 * (a + c + std::sqrt((a - c) * (a - c) + 4 * b * b));
    const double grad_angle = 0.5 * std::atan2(2 * b, a - c);  // direction of the gradient
    f.tx[i] = static_cast<float>(-std::sin(grad_angle));      // rotated 90 degrees: along the edge
    f.ty[i] = static_cast<float>(std::cos(grad_angle));
    f.strength[i] = static_cast<float>(std::sqrt(std::max(0.0, lambda1)));
  }
  return f;
}

namespace {
// One point's mark: along the edge where the gradient is strong (longer, in more
// parallel passes), the hatch direction where the image is flat; lightened and maybe
// thinned out of the plot where the pixel is brighter than the pen.
struct StrokeShaper {
  const SketchParams& params;
  const Image& grid;
  const EdgeField& edges;
  const PageTransform& T;
  double sx, sy;  // input pixels per grid cell
  double hx, hy;  // hatch direction on the page (y down)
  bool lighten;

  Stroke stroke(const Point& pt, const std::vector<float>& prob, double pen_luma, double spacing, Rng& thin) const {
    const int ix = std::clamp(static_cast<int>(pt.x), 0, grid.width - 1);
    const int iy = std::clamp(static_cast<int>(pt.y), 0, grid.height - 1);
    const size_t i = static_cast<size_t>(iy) * grid.width + ix;
    const double g = edges.strength[i];
    const double s = smoothstep(params.edge_low, params.edge_high, g);
    double dx = hx, dy = hy;
    if (g >= params.edge_low) {
      dx = edges.tx[i];
      dy = edges.ty[i];
    }
    const double len = params.mark_mm + s * (params.edge_mm - params.mark_mm);
    const int passes = 1 + static_cast<int>(std::lround(s * (params.max_passes - 1)));
    Stroke st;
    if (lighten) {
      const double y = luma01(grid.rgb[3 * i], grid.rgb[3 * i + 1], grid.rgb[3 * i + 2]) / 255.0;
      st.lighten = pen_luma < 1 ? static_cast<float>(std::max(0.0, (y - pen_luma) / (1 - pen_luma))) : 0.0f;
      st.plotted = thin.uniform() < keep_share(prob[i], st.lighten);
    }
    const Vec2 ctr = T.map(pt.x * sx, pt.y * sy);
    const double nx = -dy, ny = dx;
    st.line.pts.reserve(2 * passes);
    for (int k = 0; k < passes; ++k) {
      const double off = (k - 0.5 * (passes - 1)) * spacing;
      const double cx = ctr.x + nx * off, cy = ctr.y + ny * off;
      const double sgn = (k % 2 == 0) ? 1 : -1;  // zigzag: one pen-down for all passes
      st.line.pts.push_back({cx - sgn * dx * len / 2, cy - sgn * dy * len / 2});
      st.line.pts.push_back({cx + sgn * dx * len / 2, cy + sgn * dy * len / 2});
    }
    return st;
  }
};
}  // namespace

SketchResult sketch_strokes(const Image& image, const SketchParams& params, const Placement& placement) {
  params.validate();
  placement.validate();
  if (image.pixels() == 0) throw UserError("image has no pixels");
  const std::vector<Pen> pens = params.space == ColorSpace::Pens ? params.pens : builtin_pens(params.space, placement.pen_width_mm);
  const PageTransform T = placement.transform(image.width, image.height);
  const double mm_per_px = T.mm_per_px();
  const double cell_mm = params.cell.value > 0 ? params.cell.to_mm(mm_per_px) : params.auto_cell_mm(pens);
  const double cell_px = cell_mm / mm_per_px;
  const double gw_d = std::max(1.0, std::round(image.width / cell_px));
  const double gh_d = std::max(1.0, std::round(image.height / cell_px));
  if (gw_d * gh_d > 20e6)
    throw UserError("--cell " + std::to_string(cell_mm) + " mm gives a sampling grid of more than 20 million cells; use a larger --cell");
  SketchResult r;
  r.page = Page{T.page_w(), T.page_h(), colors::white};
  r.grid_w = static_cast<int>(gw_d);
  r.grid_h = static_cast<int>(gh_d);
  r.cell_mm = cell_mm;
  const Image grid = resize_to(image, r.grid_w, r.grid_h);
  r.prob = pen_probabilities(grid, params, pens);
  const auto& prob = r.prob;
  r.grid_origin_mm = T.map(0, 0);
  r.cell_w_mm = static_cast<double>(image.width) / r.grid_w * mm_per_px;
  r.cell_h_mm = static_cast<double>(image.height) / r.grid_h * mm_per_px;
  const EdgeField edges = edge_field(grid);
  const double hatch = params.hatch_deg * kPi / 180;
  const StrokeShaper shaper{params, grid, edges, T, static_cast<double>(image.width) / r.grid_w,
                            static_cast<double>(image.height) / r.grid_h, std::cos(hatch), -std::sin(hatch),
                            params.lighten_on()};

  // Solve every pen first so an absurd stroke count is refused before any allocation.
  std::vector<PointCount> counts(pens.size());
  double total_points = 0;
  for (size_t c = 0; c < pens.size(); ++c) total_points += (counts[c] = solve_point_count(prob[c])).m;
  if (total_points > 10e6)
    throw UserError("the sketch would have " + std::to_string(static_cast<long long>(total_points)) +
                    " strokes (more than 10 million); use a larger --cell");
  for (size_t c = 0; c < pens.size(); ++c) {
    PenStrokes ps;
    ps.pen = pens[c];
    const PointCount& pc = counts[c];
    ps.m = pc.m;
    ps.degenerate = pc.degenerate;
    const auto q = densities(prob[c], pc);
    const size_t count = static_cast<size_t>(std::llround(pc.m));
    const uint64_t pen_seed = params.seed * 0x9E3779B97F4A7C15ULL + c * 0xD1B54A32D192ED03ULL;
    const auto pts = params.sampler == SketchParams::Sampler::Random
                         ? place_points_random(q, r.grid_w, r.grid_h, count, pen_seed)
                         : place_points(q, r.grid_w, r.grid_h, count, pen_seed);
    Rng thin(pen_seed ^ 0xA5A5A5A5ULL);
    const Rgb01 pc01 = to01(ps.pen.color);
    const double pen_luma = luma01(pc01.r, pc01.g, pc01.b);
    const double spacing = ps.pen.width_mm * 0.8;
    ps.strokes.reserve(pts.size());
    for (const Point& pt : pts) ps.strokes.push_back(shaper.stroke(pt, prob[c], pen_luma, spacing, thin));
    r.pens.push_back(std::move(ps));
  }
  return r;
}

Drawing to_drawing(const SketchResult& r) {
  Drawing d;
  d.page = r.page;
  for (const auto& ps : r.pens) {
    Layer l;
    l.pen = ps.pen;
    for (const auto& s : ps.strokes)
      if (s.plotted) l.lines.push_back(s.line);
    if (!l.lines.empty()) d.layers.push_back(std::move(l));
  }
  merge_layers_by_pen(d);  // light pens before dark
  return d;
}

Drawing sketch(const Image& image, const SketchParams& params, const Placement& placement) {
  return to_drawing(sketch_strokes(image, params, placement));
}

Image render_sketch_preview(const SketchResult& r, double dpi, PreviewStyle style) {
  require_range("--preview-dpi", dpi, 10, 2400);
  const double s = dpi / 25.4;
  const double wd = std::ceil(r.page.width_mm * s), hd = std::ceil(r.page.height_mm * s);
  if (wd * hd > 200e6) throw UserError("preview would be too large; lower --preview-dpi");
  const int W = static_cast<int>(wd), H = static_cast<int>(hd);
  const size_t n = static_cast<size_t>(W) * H;
  std::vector<float> sum(3 * n, 0.0f), wsum(n, 0.0f), cov(n, 0.0f);
  for (const auto& ps : r.pens) {
    const Rgb01 pen = to01(ps.pen.color);
    const double rad = std::max(0.5, ps.pen.width_mm * s / 2);
    for (const auto& st : ps.strokes) {
      if (style == PreviewStyle::Plot && !st.plotted) continue;
      const double t = style == PreviewStyle::Paper ? st.lighten : 0.0;
      const float cr = static_cast<float>(pen.r + t * (1 - pen.r)), cg = static_cast<float>(pen.g + t * (1 - pen.g)),
                  cb = static_cast<float>(pen.b + t * (1 - pen.b));
      const auto& P = st.line.pts;
      for (size_t k = 0; k + 1 < P.size(); ++k) {
        const double ax = P[k].x * s, ay = P[k].y * s, bx = P[k + 1].x * s, by = P[k + 1].y * s;
        const int x0 = std::max(0, static_cast<int>(std::floor(std::min(ax, bx) - rad - 1)));
        const int x1 = std::min(W - 1, static_cast<int>(std::ceil(std::max(ax, bx) + rad + 1)));
        const int y0 = std::max(0, static_cast<int>(std::floor(std::min(ay, by) - rad - 1)));
        const int y1 = std::min(H - 1, static_cast<int>(std::ceil(std::max(ay, by) + rad + 1)));
        const double vx = bx - ax, vy = by - ay, vv = vx * vx + vy * vy;
        for (int y = y0; y <= y1; ++y) {
          for (int x = x0; x <= x1; ++x) {
            const double px = x + 0.5 - ax, py = y + 0.5 - ay;
            const double u = vv > 0 ? std::clamp((px * vx + py * vy) / vv, 0.0, 1.0) : 0.0;
            const double ex = px - u * vx, ey = py - u * vy;
            const double w = std::clamp(rad + 0.5 - std::sqrt(ex * ex + ey * ey), 0.0, 1.0);
            if (w <= 0) continue;
            const size_t o = static_cast<size_t>(y) * W + x;
            const float wf = static_cast<float>(w);
            sum[3 * o] += wf * cr;
            sum[3 * o + 1] += wf * cg;
            sum[3 * o + 2] += wf * cb;
            wsum[o] += wf;
            cov[o] = std::max(cov[o], wf);
          }
        }
      }
    }
  }
  Image im;
  im.width = W;
  im.height = H;
  im.rgb.resize(3 * n);
  const Rgb01 paper = to01(r.page.paper);
  const double pp[3] = {paper.r, paper.g, paper.b};
  for (size_t o = 0; o < n; ++o) {
    for (int ch = 0; ch < 3; ++ch) {
      double v = pp[ch];
      if (wsum[o] > 0) v = pp[ch] * (1 - cov[o]) + (sum[3 * o + ch] / wsum[o]) * cov[o];
      im.rgb[3 * o + ch] = static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255));
    }
  }
  return im;
}

namespace {
constexpr double kGroundToneMm = 1.0;  // the blur of the amounts, on paper
}  // namespace

hatch::PenGrid ground_grid(const Image& image, const std::vector<Pen>& pens, const Placement& placement) {
  hatch::PenGrid g;
  if (pens.empty() || pens.size() + 1 >= hatch::PenGrid::kPaper || image.width <= 0 || image.height <= 0) return g;
  const PageTransform tf = placement.transform(image.width, image.height);
  g.cell_mm = placement.pen_width_mm / 2;
  const Vec2 lo = tf.map(0, 0), hi = tf.map(image.width, image.height);
  g.origin_mm = lo;
  g.width = std::max(1, static_cast<int>(std::ceil((hi.x - lo.x) / g.cell_mm)));
  g.height = std::max(1, static_cast<int>(std::ceil((hi.y - lo.y) / g.cell_mm)));
  const Image cells = resize_to(image, g.width, g.height);
  g.pen.resize(cells.pixels());
  if (pens.size() > 1) {
    // The fields' colours carry the tone: each cell the nearest pen, or the paper.
    std::vector<Pen> candidates = pens;
    candidates.push_back(Pen{"paper", colors::white, 0});
    PenMatcher match(candidates);
    // A field's pen, not a pixel's: colours to 5 bits a channel (32,768 answers at most,
    // where a photo's cells have hundreds of thousands of colours, each 9 CIEDE2000s).
    constexpr uint8_t kUnknown = 254;
    std::vector<uint8_t> answer(32768, kUnknown);
    for (size_t i = 0; i < g.pen.size(); ++i) {
      const uint8_t* c = &cells.rgb[3 * i];
      const size_t key = (size_t{c[0]} >> 3) << 10 | (size_t{c[1]} >> 3) << 5 | (size_t{c[2]} >> 3);
      if (answer[key] == kUnknown) {
        const auto mid = [](uint8_t v) { return static_cast<uint8_t>((v & 0xf8) | 4); };
        const size_t k = match.nearest(Color{mid(c[0]), mid(c[1]), mid(c[2])});
        answer[key] = k >= pens.size() ? hatch::PenGrid::kPaper : static_cast<uint8_t>(k);
      }
      g.pen[i] = answer[key];
    }
    return hatch::settle_fields(g, pens.size());
  }
  // One pen: its lines' density is the only tone there is. Each cell wants the share of
  // the way from the paper to the pen that its colour lies (RGB, projected); one too
  // light for a direction of lines is the paper's.
  const Color p = pens[0].color;
  const double d[3] = {255.0 - p.r, 255.0 - p.g, 255.0 - p.b};
  const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  g.amount.resize(cells.pixels());
  for (size_t i = 0; i < g.pen.size(); ++i) {
    const uint8_t* c = &cells.rgb[3 * i];
    const double e[3] = {255.0 - c[0], 255.0 - c[1], 255.0 - c[2]};
    g.amount[i] = dd > 0 ? static_cast<float>(std::clamp((d[0] * e[0] + d[1] * e[1] + d[2] * e[2]) / dd, 0.0, 1.0)) : 0.0f;
  }
  // The tone as seen from a step away: what the directions follow, not the grain.
  cv::Mat amount(g.height, g.width, CV_32F, g.amount.data());
  const double sigma = kGroundToneMm / g.cell_mm;
  gaussian_blur_rows(amount, amount, sigma, cv::BORDER_REPLICATE);
  for (size_t i = 0; i < g.pen.size(); ++i)
    g.pen[i] = g.amount[i] * hatch::kFieldDirections < 0.5 ? hatch::PenGrid::kPaper : 0;
  return hatch::settle_fields(g, pens.size());
}

Drawing ground_drawing(const hatch::PenGrid& grid, const std::vector<Pen>& pens, const Placement& placement,
                       double coverage) {
  Drawing d;
  const PageTransform tf = placement.transform(1, 1);
  d.page.width_mm = tf.page_w();
  d.page.height_mm = tf.page_h();
  std::vector<Layer> layers(pens.size());
  if (!grid.pen.empty()) hatch::hatch_fields(grid, pens.size(), placement.pen_width_mm, coverage, layers);
  for (size_t k = 0; k < pens.size(); ++k) {
    if (layers[k].lines.empty()) continue;
    layers[k].pen = pens[k];
    d.layers.push_back(std::move(layers[k]));
  }
  return d;
}

}  // namespace stipplot::sketch
