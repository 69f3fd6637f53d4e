#include "methods/stipple/stipple.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "methods/stipple/pds.hpp"
#include "util/error.hpp"

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

namespace {

constexpr Color kGreyPaper{128, 128, 128};

// blank_from: grey levels at or above this get no dot at all (256 = the paper: every
// level gets dots, white ones sparsest).
std::vector<uint32_t> one_colour(int w, int h, const std::vector<uint8_t>& d, double a, double b, bool random,
                                 Rng& rng, const pds::ProgressFn& progress, int blank_from = 256) {
  auto radius = pds::RadiusTable::linear(a, b, false);
  auto order = random ? pds::random_order(d.size(), rng) : pds::grayscale_order(d, rng);
  if (blank_from < 256) {
    // grayscale order is sorted by level, so the blank pixels are a suffix
    auto cut = std::find_if(order.begin(), order.end(), [&](uint32_t i) { return d[i] >= blank_from; });
    order.erase(cut, order.end());
  }
  return pds::sample(w, h, d, radius, order, progress);
}

pds::BinaryResult binary(int w, int h, const std::vector<uint8_t>& d, const StippleParams& p, Rng& rng,
                         const pds::ProgressFn& progress) {
  auto s = pds::RadiusTable::linear(p.a_b, p.b_b, false);
  auto t = pds::RadiusTable::linear(p.a_w, p.b_w, true);
  return pds::sample_binary(w, h, d, s, t, pds::grayscale_order(d, rng), progress);
}

// Progress of part `i` of `n` equal parts (colour channels, inks).
pds::ProgressFn part(const pds::ProgressFn& all, int i, int n) {
  if (!all) return {};
  return [all, i, n](double f) { all((i + f) / n); };
}

// Binary-stipple R, G and B; a dotted pixel shows 0 (black dot), 255 (white dot) or 128
// (no dot) in each channel, so the recombined dots take 3^3 - 1 = 26 colours on the grey
// ground (the 27th is the ground itself).
void colour_layers(const Image& image, const StippleParams& p, Rng& rng, const pds::ProgressFn& progress,
                   StippleResult& out) {
  const int w = image.width, h = image.height;
  std::vector<uint8_t> state(image.pixels() * 3, 128);
  std::vector<uint8_t> any(image.pixels(), 0);
  for (int c = 0; c < 3; ++c) {
    auto r = binary(w, h, image.plane(c), p, rng, part(progress, c, 3));
    for (uint32_t i : r.black) state[size_t{i} * 3 + static_cast<size_t>(c)] = 0, any[i] = 1;
    for (uint32_t i : r.white) state[size_t{i} * 3 + static_cast<size_t>(c)] = 255, any[i] = 1;
  }
  std::map<std::array<uint8_t, 3>, size_t> layer_of;
  out.paper = kGreyPaper;
  for (uint32_t i = 0; i < static_cast<uint32_t>(any.size()); ++i) {
    if (!any[i]) continue;
    std::array<uint8_t, 3> key{state[size_t{i} * 3], state[size_t{i} * 3 + 1], state[size_t{i} * 3 + 2]};
    auto [it, inserted] = layer_of.try_emplace(key, 0);
    if (inserted) {
      Color col{key[0], key[1], key[2]};
      it->second = out.layers.size();
      out.layers.push_back({Pen{col.hex(), col, 0.3}, {}});
    }
    out.layers[it->second].dots.push_back(i);
  }
  // Stable layer order for reproducible files: by colour value.
  std::sort(out.layers.begin(), out.layers.end(), [](const StippleLayer& x, const StippleLayer& y) {
    return std::tie(x.pen.color.r, x.pen.color.g, x.pen.color.b) < std::tie(y.pen.color.r, y.pen.color.g, y.pen.color.b);
  });
}

// Ink subtracts light, so plot a separation: K = 1 - max(R,G,B) with grey component
// replacement, C = (1 - R - K)/(1 - K) etc. Each ink's coverage is stippled as a
// dark-is-dense grey image 255*(1 - coverage). Unlike the paper's one-ink methods, paper
// that needs none of an ink gets none of its dots (below 2% coverage), or every light
// area would be speckled with all four inks.
void cmyk_layers(const Image& image, const StippleParams& p, Rng& rng, const pds::ProgressFn& progress,
                 StippleResult& out) {
  const int w = image.width, h = image.height;
  const size_t n = image.pixels();
  std::array<std::vector<uint8_t>, 4> cov;
  for (auto& v : cov) v.resize(n);
  for (size_t i = 0; i < n; ++i) {
    double r = image.rgb[i * 3] / 255.0, g = image.rgb[i * 3 + 1] / 255.0, b = image.rgb[i * 3 + 2] / 255.0;
    double k = 1 - std::max({r, g, b});
    double inv = k < 1 ? 1 / (1 - k) : 0;
    double ink[4] = {(1 - r - k) * inv, (1 - g - k) * inv, (1 - b - k) * inv, k};
    for (int c = 0; c < 4; ++c)
      cov[static_cast<size_t>(c)][i] = static_cast<uint8_t>(std::lround(255 * (1 - std::clamp(ink[c], 0.0, 1.0))));
  }
  static const Pen pens[4] = {{"cyan", {0, 174, 239}, 0.3},
                              {"magenta", {236, 0, 140}, 0.3},
                              {"yellow", {255, 221, 0}, 0.3},
                              {"black", colors::black, 0.3}};
  for (int c = 0; c < 4; ++c)
    out.layers.push_back({pens[c], one_colour(w, h, cov[static_cast<size_t>(c)], p.a, p.b, false, rng, part(progress, c, 4), 250)});
}

}  // namespace

StippleResult stipple_pixels(const Image& image, const StippleParams& p, const std::function<void(double)>& progress) {
  p.validate();
  if (image.pixels() == 0) throw UserError("image has no pixels");
  if (image.pixels() >= (1ull << 32)) throw UserError("image too large for the stippler (4 Gpixel limit)");
  const int w = image.width, h = image.height;
  Rng rng(p.seed);
  StippleResult out;
  out.width = w;
  out.height = h;
  switch (p.method) {
    case StippleMethod::Random:
    case StippleMethod::Gray: {
      out.layers.push_back({Pen{"black", colors::black, 0.3},
                            one_colour(w, h, image.luma(), p.a, p.b, p.method == StippleMethod::Random, rng, progress)});
      break;
    }
    case StippleMethod::Negative: {
      // r = a + b (255-d)/255, brightest first: grayscale order on the inverted image.
      auto inv = image.luma();
      for (auto& v : inv) v = static_cast<uint8_t>(255 - v);
      out.paper = colors::black;
      out.layers.push_back({Pen{"white", colors::white, 0.3}, one_colour(w, h, inv, p.a, p.b, false, rng, progress)});
      break;
    }
    case StippleMethod::Binary: {
      auto r = binary(w, h, image.luma(), p, rng, progress);
      out.paper = kGreyPaper;
      out.layers.push_back({Pen{"black", colors::black, 0.3}, std::move(r.black)});
      out.layers.push_back({Pen{"white", colors::white, 0.3}, std::move(r.white)});
      break;
    }
    case StippleMethod::Color:
      colour_layers(image, p, rng, progress, out);
      break;
    case StippleMethod::Cmyk:
      cmyk_layers(image, p, rng, progress, out);
      break;
  }
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

}  // namespace stipplot
