#include "methods/stipple/stipple.hpp"

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include <algorithm>
#include <memory>
#include <array>
#include <cmath>
#include <limits>

#include "util/error.hpp"
#include "util/threads.hpp"

namespace stipplot {

StippleMethod parse_stipple_method(const std::string& name) {
  static const std::map<std::string, StippleMethod> m = {
      {"random", StippleMethod::Random}, {"gray", StippleMethod::Gray},     {"grey", StippleMethod::Gray},
      {"negative", StippleMethod::Negative}, {"binary", StippleMethod::Binary}, {"color", StippleMethod::Color},
      {"colour", StippleMethod::Color}, {"cmyk", StippleMethod::Cmyk}};
  auto it = m.find(name);
  if (it == m.end())
    throw UserError("--method: unknown stippling method '" + name + "' (use random, gray, negative, binary, color or cmyk)");
  return it->second;
}

const char* to_string(StippleMethod m) {
  switch (m) {
    case StippleMethod::Random: return "random";
    case StippleMethod::Gray: return "gray";
    case StippleMethod::Negative: return "negative";
    case StippleMethod::Binary: return "binary";
    case StippleMethod::Color: return "color";
    case StippleMethod::Cmyk: return "cmyk";
  }
  return "?";
}

StippleLaw parse_stipple_law(const std::string& name) {
  if (name == "tone") return StippleLaw::Tone;
  if (name == "linear") return StippleLaw::Linear;
  throw UserError("--law: expected tone or linear, got '" + name + "'");
}

void StippleParams::validate() const {
  // Radii are in pixels; beyond a few hundred a drawing has almost no dots and the
  // grid queries only get slower, so cap them rather than let a typo run for minutes.
  constexpr double kMax = 500;
  require_range("-a", a, 0, kMax);
  require_range("-b", b, 0, kMax);
  require_range("--a-b", a_b, 0, kMax);
  require_range("--b-b", b_b, 0, kMax);
  require_range("--a-w", a_w, 0, kMax);
  require_range("--b-w", b_w, 0, kMax);
}

void PageStipple::validate() const {
  require_range("--max-dot", max_dot_mm, 0.01, 100);
  require_range("tone fade", fade, 0, 1);
  require_range("linear spread", spread, 1, 1e4);
  if (relax < 0 || relax > 50) throw UserError("--relax must be an integer in [0, 50], got " + std::to_string(relax));
  const std::pair<const char*, const Length*> lengths[] = {{"-a", &a},     {"-b", &b},     {"--a-b", &a_b},
                                                          {"--b-b", &b_b}, {"--a-w", &a_w}, {"--b-w", &b_w}};
  for (const auto& [name, len] : lengths) require_nonnegative(name, len->value);
}

namespace {

constexpr Color kGreyPaper{128, 128, 128};

// The planes and passes of every method, and how each pass's dots are sampled.
// Dots of each pass in visiting order; binary passes on one plane run interleaved.
using PassDots = std::vector<std::vector<uint32_t>>;

// Progress of part `i` of `n` equal parts (colour channels, inks).
pds::ProgressFn part(const pds::ProgressFn& all, size_t i, size_t n) {
  if (!all) return {};
  return [all, i, n](double f) { all((static_cast<double>(i) + f) / static_cast<double>(n)); };
}

PassDots sample_passes(int w, int h, StippleMethod method, const std::vector<std::vector<uint8_t>>& planes,
                       const std::vector<StipplePass>& passes, const std::vector<pds::RadiusTable>& radius, Rng& rng,
                       const pds::ProgressFn& progress) {
  PassDots out(passes.size());
  for (size_t i = 0; i < passes.size(); ++i) {
    const auto& d = planes[passes[i].plane];
    const auto prog = part(progress, i, passes.size());
    if (passes[i].ink == StipplePass::Ink::Dark) {
      const auto order = method == StippleMethod::Random ? pds::random_order(d.size(), rng) : pds::grayscale_order(d, rng);
      out[i] = pds::sample(w, h, d, radius[i], order, prog);
    } else if (passes[i].ink == StipplePass::Ink::Black) {
      // Binary: the black pass and the white pass after it share the plane and run
      // step by step.
      auto r = pds::sample_binary(w, h, d, radius[i], radius[i + 1], pds::grayscale_order(d, rng), prog);
      out[i] = std::move(r.black);
      out[i + 1] = std::move(r.white);
      ++i;
    }
  }
  return out;
}

// Ink subtracts light, so plot a separation: K = 1 - max(R,G,B) with grey component
// replacement, C = (1 - R - K)/(1 - K) etc. Each ink's coverage becomes a dark-is-dense
// plane 255 * (1 - coverage).
}  // namespace

std::vector<std::vector<uint8_t>> cmyk_separation(const Image& image) {
  const size_t n = image.pixels();
  std::vector<std::vector<uint8_t>> cov(4, std::vector<uint8_t>(n));
  for (size_t i = 0; i < n; ++i) {
    double r = image.rgb[i * 3] / 255.0, g = image.rgb[i * 3 + 1] / 255.0, b = image.rgb[i * 3 + 2] / 255.0;
    double k = 1 - std::max({r, g, b});
    double inv = k < 1 ? 1 / (1 - k) : 0;
    double ink[4] = {(1 - r - k) * inv, (1 - g - k) * inv, (1 - b - k) * inv, k};
    for (int c = 0; c < 4; ++c)
      cov[static_cast<size_t>(c)][i] = static_cast<uint8_t>(std::lround(255 * (1 - std::clamp(ink[c], 0.0, 1.0))));
  }
  return cov;
}

namespace {

const Pen kCmykPens[4] = {{"cyan", {0, 174, 239}, 0.3},
                          {"magenta", {236, 0, 140}, 0.3},
                          {"yellow", {255, 221, 0}, 0.3},
                          {"black", colors::black, 0.3}};

}  // namespace

std::vector<Pen> cmyk_inks() { return {std::begin(kCmykPens), std::end(kCmykPens)}; }

namespace {

// Planes, passes and pens of each method (pens without widths: the caller's).
void method_setup(const Image& image, StippleMethod method, std::vector<std::vector<uint8_t>>& planes,
                  std::vector<StipplePass>& passes, std::vector<Pen>& pens, Color& paper) {
  using Ink = StipplePass::Ink;
  paper = colors::white;
  switch (method) {
    case StippleMethod::Random:
    case StippleMethod::Gray:
      planes = {image.luma()};
      passes = {{Ink::Dark, 0}};
      pens = {Pen{"black", colors::black, 0.3}};
      break;
    case StippleMethod::Negative: {
      // r = a + b (255-d)/255, brightest first: grayscale order on the inverted image.
      auto inv = image.luma();
      for (auto& v : inv) v = static_cast<uint8_t>(255 - v);
      planes = {std::move(inv)};
      passes = {{Ink::Dark, 0}};
      pens = {Pen{"white", colors::white, 0.3}};
      paper = colors::black;
      break;
    }
    case StippleMethod::Binary:
      planes = {image.luma()};
      passes = {{Ink::Black, 0}, {Ink::White, 0}};
      pens = {Pen{"black", colors::black, 0.3}, Pen{"white", colors::white, 0.3}};
      paper = kGreyPaper;
      break;
    case StippleMethod::Color:
      planes = {image.plane(0), image.plane(1), image.plane(2)};
      for (size_t c = 0; c < 3; ++c) {
        passes.push_back({Ink::Black, c});
        passes.push_back({Ink::White, c});
      }
      paper = kGreyPaper;
      break;
    case StippleMethod::Cmyk:
      planes = cmyk_separation(image);
      for (size_t c = 0; c < 4; ++c) {
        passes.push_back({Ink::Dark, c});
        pens.push_back(kCmykPens[c]);
      }
      break;
  }
}

// Binary-stipple R, G and B; a dotted pixel shows 0 (black dot), 255 (white dot) or 128
// (no dot) in each channel, so the recombined dots take 3^3 - 1 = 26 colours on the grey
// ground (the 27th is the ground itself). A dot's diameter is the largest of its channels'.
std::vector<StippleLayer> colour_layers(size_t n, const PassDots& dots, const std::vector<std::vector<double>>& dia) {
  std::vector<uint8_t> state(n * 3, 128);
  std::vector<double> size(dia.empty() ? 0 : n, 0.0);
  std::vector<uint8_t> any(n, 0);
  for (size_t c = 0; c < 3; ++c)
    for (size_t pass = 2 * c; pass < 2 * c + 2; ++pass)
      for (size_t k = 0; k < dots[pass].size(); ++k) {
        const uint32_t i = dots[pass][k];
        state[size_t{i} * 3 + c] = pass % 2 == 0 ? 0 : 255;
        any[i] = 1;
        if (!dia.empty()) size[i] = std::max(size[i], dia[pass][k]);
      }
  std::map<std::array<uint8_t, 3>, size_t> layer_of;
  std::vector<StippleLayer> layers;
  for (uint32_t i = 0; i < static_cast<uint32_t>(n); ++i) {
    if (!any[i]) continue;
    std::array<uint8_t, 3> key{state[size_t{i} * 3], state[size_t{i} * 3 + 1], state[size_t{i} * 3 + 2]};
    auto [it, inserted] = layer_of.try_emplace(key, 0);
    if (inserted) {
      Color col{key[0], key[1], key[2]};
      it->second = layers.size();
      layers.push_back({Pen{col.hex(), col, 0.3}, {}, {}});
    }
    layers[it->second].dots.push_back(i);
    if (!dia.empty()) layers[it->second].diameter_mm.push_back(size[i]);
  }
  // Stable layer order for reproducible files: by colour value.
  std::sort(layers.begin(), layers.end(), [](const StippleLayer& x, const StippleLayer& y) {
    return std::tie(x.pen.color.r, x.pen.color.g, x.pen.color.b) < std::tie(y.pen.color.r, y.pen.color.g, y.pen.color.b);
  });
  return layers;
}

// The passes' dots as layers: one a pass, or the 26 colours.
std::vector<StippleLayer> to_layers(StippleMethod method, size_t n, const std::vector<Pen>& pens, PassDots dots,
                                    std::vector<std::vector<double>> dia) {
  if (method == StippleMethod::Color) return colour_layers(n, dots, dia);
  std::vector<StippleLayer> layers;
  for (size_t i = 0; i < dots.size(); ++i)
    layers.push_back({pens[i], std::move(dots[i]), dia.empty() ? std::vector<double>{} : std::move(dia[i])});
  return layers;
}

std::vector<pds::RadiusTable> linear_tables(const StippleParams& p, const std::vector<StipplePass>& passes) {
  std::vector<pds::RadiusTable> t;
  for (const auto& pass : passes) {
    switch (pass.ink) {
      case StipplePass::Ink::Dark: t.push_back(pds::RadiusTable::linear(p.a, p.b, false)); break;
      case StipplePass::Ink::Black: t.push_back(pds::RadiusTable::linear(p.a_b, p.b_b, false)); break;
      case StipplePass::Ink::White: t.push_back(pds::RadiusTable::linear(p.a_w, p.b_w, true)); break;
    }
  }
  return t;
}

}  // namespace

StippleResult stipple_pixels(const Image& image, const StippleParams& p, const std::function<void(double)>& progress) {
  p.validate();
  if (image.pixels() == 0) throw UserError("image has no pixels");
  if (image.pixels() >= (1ull << 32)) throw UserError("image too large for the stippler (4 Gpixel limit)");
  Rng rng(p.seed);
  StippleResult out;
  out.width = image.width;
  out.height = image.height;
  std::vector<std::vector<uint8_t>> planes;
  std::vector<StipplePass> passes;
  std::vector<Pen> pens;
  method_setup(image, p.method, planes, passes, pens, out.paper);
  auto tables = linear_tables(p, passes);
  if (p.method == StippleMethod::Cmyk) {
    // Paper that needs none of an ink gets none of its dots (below 2% coverage), or every
    // light area would be speckled with all four inks.
    for (auto& t : tables)
      for (int v = 250; v < 256; ++v) t.r[v] = t.r2[v] = std::numeric_limits<double>::infinity();
  }
  PassDots dots = sample_passes(image.width, image.height, p.method, planes, passes, tables, rng, progress);
  out.layers = to_layers(p.method, image.pixels(), pens, std::move(dots), {});
  return out;
}

Drawing place_stipple(const StippleResult& r, const Placement& placement) {
  placement.validate();
  PageTransform tf = placement.transform(r.width, r.height);
  Drawing dr;
  dr.page = {tf.page_w(), tf.page_h(), r.paper};
  const double dia = placement.dot_diameter_mm(tf.mm_per_px());
  const uint32_t w = static_cast<uint32_t>(r.width);
  for (const auto& sl : r.layers) {
    Layer l;
    l.pen = sl.pen;
    l.pen.width_mm = placement.pen_width_mm;
    l.dots.reserve(sl.dots.size());
    for (uint32_t i : sl.dots) l.dots.push_back({tf.map(i % w + 0.5, i / w + 0.5), dia});
    dr.layers.push_back(std::move(l));
  }
  return dr;
}

Drawing stipple(const Image& image, const StippleParams& params, const Placement& placement,
                const std::function<void(double)>& progress) {
  placement.validate();
  return place_stipple(stipple_pixels(image, params, progress), placement);
}

// ---- on the page ----

StippleCanvas prepare_stipple(const Image& image, StippleMethod method, const Placement& placement, double cell_mm) {
  placement.validate();
  StippleCanvas c;
  c.method = method;
  c.pen_mm = placement.pen_width_mm;
  const PageTransform tf = placement.transform(image.width, image.height);
  c.grid = make_working_grid(image, tf, cell_mm);
  if (c.grid.image.pixels() >= (1ull << 32)) throw UserError("working grid too large for the stippler");
  c.page = {tf.page_w(), tf.page_h(), colors::white};
  c.dot_mm = std::max(placement.dot_diameter_mm(tf.mm_per_px()), c.pen_mm);
  method_setup(c.grid.image, method, c.planes, c.passes, c.pens, c.page.paper);
  for (auto& p : c.pens) p.width_mm = c.pen_mm;
  return c;
}

double pass_tone(StipplePass::Ink ink, int level) {
  const double v = level / 255.0;
  switch (ink) {
    case StipplePass::Ink::Dark: return 1 - v;
    // On grey paper: black darkens the lower half of the tones, white lightens the upper.
    case StipplePass::Ink::Black: return std::max(0.0, 1 - 2 * v);
    case StipplePass::Ink::White: return std::max(0.0, 2 * v - 1);
  }
  return 0;
}

LevelDots level_dots(const StippleCanvas& c, size_t pass, const PageStipple& law, double mm_per_px) {
  law.validate();
  const StipplePass::Ink ink = c.passes.at(pass).ink;
  LevelDots out;
  const double cell = c.grid.cell_mm;
  if (law.law == StippleLaw::Linear) {
    const double s = law.spread / cell;
    auto mm = [&](const Length& l) { return l.to_mm(mm_per_px); };
    pds::RadiusTable t = ink == StipplePass::Ink::Black ? pds::RadiusTable::linear(mm(law.a_b) * s, mm(law.b_b) * s, false)
                         : ink == StipplePass::Ink::White ? pds::RadiusTable::linear(mm(law.a_w) * s, mm(law.b_w) * s, true)
                                                          : pds::RadiusTable::linear(mm(law.a) * s, mm(law.b) * s, false);
    out.radius = t;
    out.diameter_mm.fill(c.dot_mm);
    return out;
  }
  ToneLaw tl;
  tl.pen_mm = c.pen_mm;
  tl.max_dot_mm = std::max(law.max_dot_mm, c.pen_mm);
  tl.fade = law.fade;
  if (pass < law.pass_curve.size() && !law.pass_curve[pass].empty()) tl.curve = &law.pass_curve[pass];
  for (int v = 0; v < 256; ++v) {
    const double u = pass_tone(ink, v);
    const double r = tl.spacing_mm(u) / cell;
    out.radius.r[v] = r;
    out.radius.r2[v] = r * r;
    out.diameter_mm[static_cast<size_t>(v)] = tl.dot_mm(u);
  }
  // The table's interpolation must not let the radius shrink as the ink lightens (the
  // visiting order's direction), which would crowd light dots against dark ones.
  const bool lighter_up = ink != StipplePass::Ink::White;  // dark and black: level up = less ink
  for (int i = 1; i < 256; ++i) {
    const int v = lighter_up ? i : 255 - i, prev = lighter_up ? i - 1 : 256 - i;
    if (out.radius.none(static_cast<uint8_t>(v)) || out.radius.none(static_cast<uint8_t>(prev))) continue;
    if (out.radius.r[v] < out.radius.r[prev]) {
      out.radius.r[v] = out.radius.r[prev];
      out.radius.r2[v] = out.radius.r2[prev];
    }
  }
  return out;
}

namespace {
// Each dot's diameter from the mean tone over the disc its centre's tone would draw, so
// its ink (D^2 ~ tone) matches the tone it covers; and no larger than reaches a cell
// whose tone is lower by more than a half (a strong edge), so dark dots stop at the edge
// of a highlight (a star on a night sky, a white line) instead of closing it.
std::vector<double> footprint_diameters(const StippleCanvas& c, size_t pass, const PageStipple& law,
                                       const std::vector<Vec2>& dots) {
  ToneLaw tl;
  tl.pen_mm = c.pen_mm;
  tl.max_dot_mm = std::max(law.max_dot_mm, c.pen_mm);
  tl.fade = law.fade;
  std::array<double, 256> tone{};
  for (int v = 0; v < 256; ++v) tone[static_cast<size_t>(v)] = pass_tone(c.passes[pass].ink, v);
  const auto& plane = c.planes[c.passes[pass].plane];
  const int w = c.grid.image.width, h = c.grid.image.height;
  const double cell = c.grid.cell_mm;
  std::vector<double> out;
  out.reserve(dots.size());
  for (const Vec2& p : dots) {
    const int x = std::clamp(static_cast<int>(p.x), 0, w - 1), y = std::clamp(static_cast<int>(p.y), 0, h - 1);
    const size_t idx = static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x);
    const double centre = tone[plane[idx]];
    const double rad = 0.5 * tl.dot_mm(centre) / cell;
    const int ri = static_cast<int>(rad);
    double sum = 0, light_d2 = std::numeric_limits<double>::infinity();
    int n = 0;
    for (int dy = -ri; dy <= ri; ++dy) {
      const int yy = y + dy;
      if (yy < 0 || yy >= h) continue;
      const int hw = static_cast<int>(std::sqrt(std::max(0.0, rad * rad - dy * dy)));
      const size_t row = static_cast<size_t>(yy) * static_cast<size_t>(w);
      for (int xx = std::max(0, x - hw); xx <= std::min(w - 1, x + hw); ++xx) {
        const double t = tone[plane[row + static_cast<size_t>(xx)]];
        sum += t, ++n;
        if (t < centre - 0.5) light_d2 = std::min(light_d2, static_cast<double>((xx - x) * (xx - x) + dy * dy));
      }
    }
    double d = tl.dot_mm(n ? sum / n : centre);
    // The highlight's nearest cell is at its centre; its edge half a cell nearer.
    if (std::isfinite(light_d2)) d = std::min(d, std::max(c.pen_mm, 2 * (std::sqrt(light_d2) - 0.5) * cell));
    out.push_back(d);
  }
  return out;
}
}  // namespace

// Lloyd relaxation of one pass's dots (Secord's weighted Voronoi stippling): each dot
// moves to the centroid of the grid cells nearest to it, weighted by the density the
// law asks for there, 1/r^4 (a centroidal pattern's density grows as the square root
// of its weight, so it keeps the sampled density, 1/r^2), `iterations` times. A dot
// claims the cells within 1.5 of its own spacing (a nearest-dot buffer), so a pass costs
// O(cells x overlap); cells that get no dots (infinite r) weigh nothing, so dots never
// drift into paper left blank. It evens the pattern's spacing: the blurred drawing is
// then far less grainy than the sampled pattern, whose dots fall at random within it.
void relax_points(std::vector<Vec2>& pts, const std::vector<uint8_t>& plane, const pds::RadiusTable& radius, int w,
                  int h, int iterations) {
  const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
  std::array<double, 256> weight{};
  for (int v = 0; v < 256; ++v)
    weight[static_cast<size_t>(v)] = radius.none(static_cast<uint8_t>(v)) ? 0 : 1 / std::pow(radius.r[v], 4);
  // Not cleared here: each band fills its own rows of `best` below, and of `owner` on the
  // first pass (on its thread, which then takes the pages' first-touch faults: a 6.7M-cell
  // grid's 53 MB); `owner` is read only where `best` was set.
  const std::unique_ptr<float[]> best(new float[n]);
  const std::unique_ptr<uint32_t[]> owner(new uint32_t[n]);
  struct Window {
    int x0, x1, y0, y1;
  };
  std::vector<Window> win(pts.size());
  // Parallel without changing a bit (util/threads.hpp): the cells' nearest dots are found in
  // bands of rows, each band taking the dots that reach it in index order, as one pass over
  // all dots would.
  constexpr int kBandRows = 16;
  const int bands = (h + kBandRows - 1) / kBandRows;
  std::vector<std::vector<uint32_t>> reaching(static_cast<size_t>(bands));
  struct Sum {
    double x = 0, y = 0, w = 0;
  };
  std::vector<Sum> sums(pts.size());
  constexpr int kSumRows = 64;
  const int sum_bands = (h + kSumRows - 1) / kSumRows;
  struct Run {  // cells x0..x1 of row y, all dot k's
    uint32_t k, y, x0, x1;
  };
  // A band's runs of dots whose windows cross its edges, by how many bands above it the
  // dot's window starts.
  std::vector<std::vector<std::vector<Run>>> crossing_runs(static_cast<size_t>(sum_bands));
  // The windows and the bands they reach on every thread: each thread a block of dots
  // in index order, its own list a band, the blocks' lists joined in order (so each
  // band's list is in index order on any thread count).
  const int parts = pts.size() >= 20'000 ? std::max(1, thread_count()) : 1;
  std::vector<std::vector<std::vector<uint32_t>>> part_reaching(
      static_cast<size_t>(parts), std::vector<std::vector<uint32_t>>(static_cast<size_t>(bands)));
  for (int it = 0; it < iterations; ++it) {
#pragma omp parallel for num_threads(parts) schedule(static, 1) if (parts > 1)
    for (int t = 0; t < parts; ++t) {
      auto& mine = part_reaching[static_cast<size_t>(t)];
      for (auto& r : mine) r.clear();
      const size_t from = pts.size() * static_cast<size_t>(t) / static_cast<size_t>(parts),
                   to = pts.size() * static_cast<size_t>(t + 1) / static_cast<size_t>(parts);
      for (uint32_t k = static_cast<uint32_t>(from); k < to; ++k) {
        const int cx = std::clamp(static_cast<int>(pts[k].x), 0, w - 1), cy = std::clamp(static_cast<int>(pts[k].y), 0, h - 1);
        const uint8_t v = plane[static_cast<size_t>(cy) * static_cast<size_t>(w) + static_cast<size_t>(cx)];
        const double reach = 1.5 * (radius.none(v) ? radius.min() : radius.r[v]);
        Window& wk = win[k];
        wk.x0 = std::max(0, static_cast<int>(pts[k].x - reach)), wk.x1 = std::min(w - 1, static_cast<int>(pts[k].x + reach));
        wk.y0 = std::max(0, static_cast<int>(pts[k].y - reach)), wk.y1 = std::min(h - 1, static_cast<int>(pts[k].y + reach));
        for (int b = wk.y0 / kBandRows; wk.y0 <= wk.y1 && b <= wk.y1 / kBandRows; ++b)
          mine[static_cast<size_t>(b)].push_back(k);
      }
    }
#pragma omp parallel for schedule(dynamic, 8) if (parts > 1)
    for (int b = 0; b < bands; ++b) {
      auto& r = reaching[static_cast<size_t>(b)];
      r.clear();
      for (int t = 0; t < parts; ++t) {
        const auto& mine = part_reaching[static_cast<size_t>(t)][static_cast<size_t>(b)];
        r.insert(r.end(), mine.begin(), mine.end());
      }
    }
#pragma omp parallel for schedule(dynamic, 8)
    for (int b = 0; b < bands; ++b) {
      const int by0 = b * kBandRows, by1 = std::min(h, by0 + kBandRows) - 1;
      std::fill(best.get() + static_cast<size_t>(by0) * static_cast<size_t>(w),
                best.get() + static_cast<size_t>(by1 + 1) * static_cast<size_t>(w), std::numeric_limits<float>::infinity());
      // The first pass writes its rows of `owner` before the loop below reads them: a fresh
      // page read first is the kernel's zero page, and the write after it a copy-on-write
      // fault that flushes every core's TLB (perf: do_wp_page under this loop, 4.5 % of a
      // 2-thread run's samples in the flushes alone, the other thread's code slowed besides).
      if (it == 0)
        std::fill(owner.get() + static_cast<size_t>(by0) * static_cast<size_t>(w),
                  owner.get() + static_cast<size_t>(by1 + 1) * static_cast<size_t>(w), 0u);
      std::vector<double> dx2;  // (x + 0.5 - dot's x)^2 across its window, as each row has it
      for (const uint32_t k : reaching[static_cast<size_t>(b)]) {
        const Window& wk = win[k];
        dx2.resize(static_cast<size_t>(wk.x1 - wk.x0 + 1));
        for (int x = wk.x0; x <= wk.x1; ++x) {
          const double dx = x + 0.5 - pts[k].x;
          dx2[static_cast<size_t>(x - wk.x0)] = dx * dx;
        }
        for (int y = std::max(wk.y0, by0); y <= std::min(wk.y1, by1); ++y) {
          const double dy = y + 0.5 - pts[k].y, dy2 = dy * dy;
          const size_t row = static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(wk.x0);
          float* __restrict bp = best.get() + row;
          uint32_t* __restrict op = owner.get() + row;
          const double* __restrict d = dx2.data();
          size_t x = 0;
#ifdef __SSE2__
          // Four cells at a time (SSE2 is every x86-64's): the same sums, roundings and
          // strict comparison as the loop below, so the same bits.
          const __m128d vdy2 = _mm_set1_pd(dy2);
          const __m128i vk = _mm_set1_epi32(static_cast<int>(k));
          for (; x + 4 <= dx2.size(); x += 4) {
            const __m128 lo = _mm_cvtpd_ps(_mm_add_pd(_mm_loadu_pd(d + x), vdy2));
            const __m128 hi = _mm_cvtpd_ps(_mm_add_pd(_mm_loadu_pd(d + x + 2), vdy2));
            const __m128 d2 = _mm_movelh_ps(lo, hi);
            const __m128 b4 = _mm_loadu_ps(bp + x);
            const __m128 nearer = _mm_cmplt_ps(d2, b4);
            _mm_storeu_ps(bp + x, _mm_or_ps(_mm_and_ps(nearer, d2), _mm_andnot_ps(nearer, b4)));
            const __m128i m = _mm_castps_si128(nearer);
            const __m128i o4 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(op + x));
            _mm_storeu_si128(reinterpret_cast<__m128i*>(op + x), _mm_or_si128(_mm_and_si128(m, vk), _mm_andnot_si128(m, o4)));
          }
#endif
          for (; x < dx2.size(); ++x) {
            const float d2 = static_cast<float>(d[x] + dy2);
            const bool nearer = d2 < bp[x];
            bp[x] = nearer ? d2 : bp[x];
            op[x] = nearer ? k : op[x];
          }
        }
      }
    }
    // Each dot's centroid: its cells summed in row order, the order a walk over its own
    // window takes them, so its sums are the same bit for bit however the work is split.
    // Bands of rows in parallel, each summing in one pass over its cells (each cell read
    // once) the dots whose windows lie inside it, and noting the runs of cells of the
    // dots whose windows cross a band's edge (a few in ten). Those are summed in rounds:
    // round p, on every band at once, the runs of the dots whose windows start p bands
    // above it, so each such dot gets its rows in order, one band a round. A run of one
    // dot's cells along a row is summed in registers, then stored. (A run has no gaps: a
    // cell between two of a dot's cells on a row lies in its window, so a dot reaches it.)
    std::fill(sums.begin(), sums.end(), Sum{});
    auto band_of = [&](uint32_t k) {  // the band holding k's whole window, or -1
      const Window& wk = win[k];
      return wk.y0 <= wk.y1 && wk.y0 / kSumRows == wk.y1 / kSumRows ? wk.y0 / kSumRows : -1;
    };
    constexpr uint32_t kNoRun = std::numeric_limits<uint32_t>::max();
#pragma omp parallel for schedule(dynamic, 1)
    for (int b = 0; b < sum_bands; ++b) {
      std::vector<std::vector<Run>>& runs = crossing_runs[static_cast<size_t>(b)];
      for (auto& r : runs) r.clear();
      for (int y = b * kSumRows; y < std::min(h, (b + 1) * kSumRows); ++y) {
        const size_t row = static_cast<size_t>(y) * static_cast<size_t>(w);
        uint32_t run = kNoRun;
        int run_x0 = 0, run_x1 = 0;
        bool mine = false;  // the run's dot lies inside this band
        Sum s;
        auto end_run = [&] {
          if (run == kNoRun) return;
          if (mine) sums[run] = s;
          else {
            const size_t above = static_cast<size_t>(b - win[run].y0 / kSumRows);
            if (runs.size() <= above) runs.resize(above + 1);
            runs[above].push_back({run, static_cast<uint32_t>(y), static_cast<uint32_t>(run_x0), static_cast<uint32_t>(run_x1)});
          }
        };
        for (int x = 0; x < w; ++x) {
          const size_t i = row + static_cast<size_t>(x);
          if (!std::isfinite(best[i])) continue;  // no dot reached it (owner is stale)
          if (owner[i] != run) {
            end_run();
            run = owner[i];
            run_x0 = x;
            mine = band_of(run) == b;
            if (mine) s = sums[run];
          }
          run_x1 = x;
          if (!mine) continue;
          const double wt = weight[plane[i]];
          s.x += wt * (x + 0.5), s.y += wt * (y + 0.5), s.w += wt;
        }
        end_run();
      }
    }
    size_t rounds = 0;
    for (const auto& runs : crossing_runs) rounds = std::max(rounds, runs.size());
    for (size_t round = 0; round < rounds; ++round) {
#pragma omp parallel for schedule(dynamic, 1)
      for (int b = 0; b < sum_bands; ++b) {
        if (crossing_runs[static_cast<size_t>(b)].size() <= round) continue;
        for (const Run& r : crossing_runs[static_cast<size_t>(b)][round]) {
          const size_t row = static_cast<size_t>(r.y) * static_cast<size_t>(w);
          const int y = static_cast<int>(r.y);
          Sum s = sums[r.k];
          for (int x = static_cast<int>(r.x0); x <= static_cast<int>(r.x1); ++x) {
            const double wt = weight[plane[row + static_cast<size_t>(x)]];
            s.x += wt * (x + 0.5), s.y += wt * (y + 0.5), s.w += wt;
          }
          sums[r.k] = s;
        }
      }
    }
#pragma omp parallel for schedule(static) if (parts > 1)
    for (size_t k = 0; k < pts.size(); ++k)
      if (sums[k].w > 0) pts[k] = {sums[k].x / sums[k].w, sums[k].y / sums[k].w};
  }
}

Drawing stipple_on_page(const StippleCanvas& c, const PageStipple& law, double mm_per_px, uint64_t seed,
                        const std::function<void(double)>& progress) {
  const int w = c.grid.image.width, h = c.grid.image.height;
  std::vector<LevelDots> levels;
  std::vector<pds::RadiusTable> tables;
  for (size_t i = 0; i < c.passes.size(); ++i) {
    levels.push_back(level_dots(c, i, law, mm_per_px));
    tables.push_back(levels.back().radius);
  }
  Rng rng(seed);
  PassDots dots = sample_passes(w, h, c.method, c.planes, c.passes, tables, rng, progress);
  // Positions in cell coordinates, jittered within the cell from their own stream (so the
  // dots chosen do not depend on it), then relaxed.
  Rng jitter(seed ^ 0x6a09e667f3bcc909ULL);
  const uint32_t gw = static_cast<uint32_t>(w);
  std::vector<std::vector<Vec2>> pos(dots.size());
  for (size_t i = 0; i < dots.size(); ++i)
    for (uint32_t idx : dots[i]) pos[i].push_back({idx % gw + jitter.uniform(), idx / gw + jitter.uniform()});
  const bool tone = law.law == StippleLaw::Tone;
  // Colour merges its channels' dots by cell: they must stay on their cells.
  if (tone && c.method != StippleMethod::Color)
    for (size_t i = 0; i < dots.size(); ++i) relax_points(pos[i], c.planes[c.passes[i].plane], tables[i], w, h, law.relax);
  std::vector<std::vector<double>> dia(dots.size());
  for (size_t i = 0; i < dots.size(); ++i) {
    const auto& plane = c.planes[c.passes[i].plane];
    if (tone) {
      dia[i] = footprint_diameters(c, i, law, pos[i]);
    } else {
      for (uint32_t idx : dots[i]) dia[i].push_back(levels[i].diameter_mm[plane[idx]]);
    }
  }
  std::vector<StippleLayer> layers;
  std::vector<std::vector<Vec2>> layer_pos;
  if (c.method == StippleMethod::Color) {
    layers = colour_layers(c.grid.image.pixels(), dots, dia);
    for (const auto& sl : layers) {
      layer_pos.emplace_back();
      for (uint32_t idx : sl.dots) layer_pos.back().push_back({idx % gw + jitter.uniform(), idx / gw + jitter.uniform()});
    }
  } else {
    for (size_t i = 0; i < dots.size(); ++i) layers.push_back({c.pens[i], std::move(dots[i]), std::move(dia[i])});
    layer_pos = std::move(pos);
  }
  Drawing d;
  d.page = c.page;
  for (size_t li = 0; li < layers.size(); ++li) {
    const StippleLayer& sl = layers[li];
    Layer l;
    l.pen = sl.pen;
    l.pen.width_mm = c.pen_mm;
    l.dots.reserve(sl.dots.size());
    for (size_t k = 0; k < sl.dots.size(); ++k) {
      const double x = std::clamp(layer_pos[li][k].x, 0.0, static_cast<double>(w)),
                   y = std::clamp(layer_pos[li][k].y, 0.0, static_cast<double>(h));
      // Within the image's rectangle: a fill no wider than twice its distance to the edge.
      const double edge = std::min({x, y, w - x, h - y}) * c.grid.cell_mm;
      l.dots.push_back({c.grid.to_page(x, y), std::max(std::min(sl.diameter_mm[k], 2 * edge), c.pen_mm)});
    }
    d.layers.push_back(std::move(l));
  }
  return d;
}

std::vector<LevelCoverage> measured_coverage(const StippleCanvas& c, const Drawing& d) {
  const int w = c.grid.image.width, h = c.grid.image.height;
  const int S = 2;  // raster cells a grid cell, each way
  const int rw = w * S, rh = h * S;
  const double px = c.grid.cell_mm / S;
  std::vector<LevelCoverage> out(c.passes.size());
  std::vector<uint8_t> ink(static_cast<size_t>(rw) * static_cast<size_t>(rh));
  for (size_t i = 0; i < c.passes.size() && i < d.layers.size(); ++i) {
    std::fill(ink.begin(), ink.end(), uint8_t{0});
    for (const Dot& dot : d.layers[i].dots) {
      const double cx = (dot.c.x - c.grid.origin_mm.x) / px, cy = (dot.c.y - c.grid.origin_mm.y) / px;
      const double r = 0.5 * dot.diameter / px;
      const int y0 = std::max(0, static_cast<int>(cy - r)), y1 = std::min(rh - 1, static_cast<int>(cy + r) + 1);
      for (int y = y0; y <= y1; ++y) {
        const double dy = y + 0.5 - cy, half2 = r * r - dy * dy;
        if (half2 < 0) continue;
        const double half = std::sqrt(half2);
        const int x0 = std::max(0, static_cast<int>(std::ceil(cx - half - 0.5))),
                  x1 = std::min(rw - 1, static_cast<int>(std::floor(cx + half - 0.5)));
        if (x1 >= x0) std::fill_n(&ink[static_cast<size_t>(y) * rw + static_cast<size_t>(x0)], x1 - x0 + 1, uint8_t{1});
      }
    }
    const auto& plane = c.planes[c.passes[i].plane];
    for (int y = 0; y < rh; ++y)
      for (int x = 0; x < rw; ++x) {
        const uint8_t v = plane[static_cast<size_t>(y / S) * static_cast<size_t>(w) + static_cast<size_t>(x / S)];
        out[i].cells[v] += 1;
        out[i].covered[v] += ink[static_cast<size_t>(y) * rw + static_cast<size_t>(x)];
      }
  }
  return out;
}

}  // namespace stipplot
