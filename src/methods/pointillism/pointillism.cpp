#include "methods/pointillism/pointillism.hpp"

#include "methods/hatch/pen_fields.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "methods/palette.hpp"
#include "util/error.hpp"
#include "util/even_share.hpp"

namespace stipplot::pointillism {

void Params::validate() const {
  require_positive("--radius", radius_px);
  require_range("--radius", radius_px, 1e-3, 1000);
  require_range("--alpha-ebauche", alpha_ebauche, 1e-3, 4);
  require_range("--alpha-strokes", alpha_strokes, 1e-3, 4);
  if (regions < 1 || regions > 100) throw UserError("--regions must be an integer in [1, 100], got " + std::to_string(regions));
  require_range("--weight", weight, 0, 100);
  require_range("--chroma", chroma, 0, 200);
  require_range("--grey-chroma", grey_chroma, 0, 200);
  require_range("--blur", blur_sigma, 0, 100);
  if (ebauche_misses > 1'000'000'000) throw UserError("--ebauche-misses must be at most 1e9 (0 = no limit)");
  // Below one pixel every pixel would become a circle: millions of them, pointless.
  if (ebauche && 2 * alpha_ebauche * radius_px < 1)
    throw UserError("--alpha-ebauche x 2 x --radius must be at least 1 pixel (circles closer than a pixel)");
  if (!ebauche && !strokes) throw UserError("--no-ebauche and --no-strokes together leave nothing to draw");
  if (2 * alpha_strokes * radius_px < 1)
    throw UserError("--alpha-strokes x 2 x --radius must be at least 1 pixel (circles closer than a pixel)");
}

void complementary_pair(double a, double b, double R, lab::Lab& pure, lab::Lab& complement) {
  const double c = std::hypot(a, b);
  const double ua = c > 0 ? a / c : 1, ub = c > 0 ? b / c : 0;
  pure.a = R * ua;
  pure.b = R * ub;
  complement.a = -pure.a;
  complement.b = -pure.b;
}

size_t pure_count(size_t n, const lab::Lab& pk, const lab::Lab& pi, const lab::Lab& pj, double weight) {
  const double dki = std::hypot(pk.a - pi.a, pk.b - pi.b);
  const double dkj = std::hypot(pk.a - pj.a, pk.b - pj.b);
  const double sum = dki + dkj;
  // p_k at the origin on a zero circle: nothing to divide; all dots take the "pure" colour.
  const double share = sum > 0 ? dkj / sum : 1.0;
  const double npi = std::round(weight * static_cast<double>(n) * share);
  return static_cast<size_t>(std::clamp(npi, 0.0, static_cast<double>(n)));
}

std::vector<uint32_t> random_order(size_t n, Rng& rng) {
  std::vector<uint32_t> out(n);
  if (n == 0) return out;
  const uint32_t buckets = static_cast<uint32_t>(std::max<size_t>(1, n / 4096));
  // Two passes over the same random bucket choices: count, then scatter.
  std::vector<size_t> start(buckets + 1, 0);
  Rng again = rng;
  for (size_t i = 0; i < n; ++i) ++start[rng.below(buckets) + 1];
  for (uint32_t k = 0; k < buckets; ++k) start[k + 1] += start[k];
  std::vector<size_t> fill(start.begin(), start.end() - 1);
  for (size_t i = 0; i < n; ++i) out[fill[again.below(buckets)]++] = static_cast<uint32_t>(i);
  for (uint32_t k = 0; k < buckets; ++k) {
    uint32_t* b = out.data() + start[k];
    const size_t len = start[k + 1] - start[k];
    for (size_t i = len; i > 1; --i) std::swap(b[i - 1], b[rng.below(static_cast<uint32_t>(i))]);
  }
  return out;
}

namespace {
// d < D over integer squared distances: d2 < D^2 iff d2 <= ceil(D^2) - 1.
double strict_r2(double min_dist) { return std::ceil(min_dist * min_dist - 1e-9) - 1; }
}  // namespace

std::vector<uint32_t> equal_disc_pds(int width, int height, double min_dist, const std::vector<uint32_t>& order,
                                     size_t max_misses) {
  // Equal discs make the test a table lookup: a placed disc stamps every pixel closer
  // than min_dist as blocked (O(min_dist^2) each, row runs), and a candidate only reads
  // its own byte. The same predicate as checking every neighbour, far fewer operations.
  const double r2 = strict_r2(min_dist);
  std::vector<uint8_t> blocked(static_cast<size_t>(width) * height, 0);
  const int R = r2 < 0 ? -1 : static_cast<int>(std::floor(std::sqrt(r2)));
  std::vector<int> half(static_cast<size_t>(std::max(R, 0)) + 1, 0);
  for (int dy = 0; dy <= R; ++dy) {
    int hw = 0;
    while ((hw + 1) * (hw + 1) + dy * dy <= r2) ++hw;
    half[dy] = hw;
  }
  std::vector<uint32_t> dots;
  const uint32_t w = static_cast<uint32_t>(width);
  size_t misses = 0;
  for (uint32_t idx : order) {
    if (blocked[idx]) {
      if (max_misses && ++misses >= max_misses) break;
      continue;
    }
    misses = 0;
    dots.push_back(idx);
    const int x = static_cast<int>(idx % w), y = static_cast<int>(idx / w);
    for (int dy = -R; dy <= R; ++dy) {
      const int yy = y + dy;
      if (yy < 0 || yy >= height) continue;
      const int hw = half[static_cast<size_t>(std::abs(dy))];
      const int x0 = std::max(0, x - hw), x1 = std::min(width - 1, x + hw);
      std::fill_n(&blocked[static_cast<size_t>(yy) * w + x0], x1 - x0 + 1, uint8_t{1});
    }
  }
  return dots;
}

std::vector<uint32_t> equal_disc_pds_naive(int width, int, double min_dist, const std::vector<uint32_t>& order) {
  const double r2 = strict_r2(min_dist);
  std::vector<uint32_t> dots;
  std::vector<std::pair<int, int>> placed;
  const uint32_t w = static_cast<uint32_t>(width);
  for (uint32_t idx : order) {
    const int x = static_cast<int>(idx % w), y = static_cast<int>(idx / w);
    bool free = true;
    for (const auto& [px, py] : placed) {
      const int dx = px - x, dy = py - y;
      if (dx * dx + dy * dy <= r2) {
        free = false;
        break;
      }
    }
    if (free) {
      placed.emplace_back(x, y);
      dots.push_back(idx);
    }
  }
  return dots;
}

void prepare_colour_tables() {
  cv::Mat px(1, 1, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5)), lab;
  cv::cvtColor(px, lab, cv::COLOR_RGB2Lab);
}

namespace {

cv::Mat rgb_mat(const Image& im) {
  return cv::Mat(im.height, im.width, CV_8UC3, const_cast<uint8_t*>(im.rgb.data()));
}

Color pixel(const Image& im, uint32_t idx) {
  const uint8_t* p = &im.rgb[static_cast<size_t>(idx) * 3];
  return {p[0], p[1], p[2]};
}

// Labels every pixel by the L* level of the blurred image and sums its L*, a*, b*.
// Works in strips of rows so the float Lab copy stays small on 12-megapixel photos.
void split_regions(const Image& image, const Params& p, Result& r) {
  cv::Mat src = rgb_mat(image), blurred;
  if (p.blur_sigma > 0) cv::GaussianBlur(src, blurred, cv::Size(0, 0), p.blur_sigma, p.blur_sigma, cv::BORDER_REFLECT);
  else blurred = src;
  const int m = p.regions;
  r.regions.assign(static_cast<size_t>(m), Region{});
  std::vector<double> sumL(m, 0), suma(m, 0), sumb(m, 0);
  r.labels.resize(image.pixels());
  const int strip = 256;
  cv::Mat f, labm;
  for (int y0 = 0; y0 < image.height; y0 += strip) {
    const int rows = std::min(strip, image.height - y0);
    blurred.rowRange(y0, y0 + rows).convertTo(f, CV_32FC3, 1.0 / 255);
    cv::cvtColor(f, labm, cv::COLOR_RGB2Lab);  // float: L in [0,100], sRGB gamma, D65
    for (int y = 0; y < rows; ++y) {
      const float* row = labm.ptr<float>(y);
      uint8_t* lab_out = &r.labels[static_cast<size_t>(y0 + y) * image.width];
      for (int x = 0; x < image.width; ++x) {
        const double L = row[3 * x], a = row[3 * x + 1], b = row[3 * x + 2];
        const int k = std::clamp(static_cast<int>(std::floor(L * m / 100.0)), 0, m - 1);
        lab_out[x] = static_cast<uint8_t>(k);
        ++r.regions[k].pixels;
        sumL[k] += L;
        suma[k] += a;
        sumb[k] += b;
      }
    }
  }
  for (int k = 0; k < m; ++k) {
    Region& g = r.regions[k];
    if (g.pixels == 0) continue;
    const double n = static_cast<double>(g.pixels);
    g.L = sumL[k] / n;
    g.mean = {g.L, suma[k] / n, sumb[k] / n};
    const double c = std::hypot(g.mean.a, g.mean.b);
    g.grey = c < p.grey_chroma || c == 0;
    if (p.chroma > 0) {
      g.circle = p.chroma;
    } else {
      // Gamut-safe: the largest circle on which both p_i and p_j are displayable at the
      // region's L*.
      const double h = std::atan2(g.mean.b, g.mean.a);
      g.circle = std::min(lab::max_chroma(g.L, h), lab::max_chroma(g.L, h + M_PI));
    }
    if (!g.grey) {
      complementary_pair(g.mean.a, g.mean.b, g.circle, g.pure, g.complement);
    } else {
      // Near grey (the paper leaves it unsolved): the hue of p_k is then noise (JPEG,
      // white balance), and the construction would lay saturated pure and complement
      // dots of that random hue over a grey area -- coloured confetti, mixing to grey
      // only on average (with W = 1 the dots' mean a*b* is p_k). So below the threshold
      // the dots take the region's own colour: no complement, no invented hue.
      g.pure = g.mean;
      g.complement = g.mean;
    }
    g.pure.L = g.complement.L = g.L;
  }
}

}  // namespace

Result paint(const Image& image, const Params& p) {
  p.validate();
  if (image.pixels() == 0) throw UserError("pointillism: empty image");
  if (image.pixels() > 0xffffffffull) throw UserError("pointillism: image too large");
  Result r;
  r.width = image.width;
  r.height = image.height;
  r.radius_px = p.radius_px;
  split_regions(image, p, r);

  // Separate streams, so the strokes are the same with or without the ebauche.
  Rng rng_ebauche(p.seed), rng(p.seed ^ 0x5eb0a7d1c0ffeeULL);
  const size_t n = image.pixels();
  const uint32_t w = static_cast<uint32_t>(image.width);
  auto centre = [w](uint32_t idx, PaintDot& d) {
    d.x = static_cast<float>(idx % w) + 0.5f;
    d.y = static_cast<float>(idx / w) + 0.5f;
  };

  if (p.ebauche) {
    const auto order = random_order(n, rng_ebauche);
    const auto dots =
        equal_disc_pds(image.width, image.height, 2 * p.alpha_ebauche * p.radius_px, order, p.ebauche_misses);
    r.ebauche.resize(dots.size());
    for (size_t i = 0; i < dots.size(); ++i) {
      PaintDot& d = r.ebauche[i];
      centre(dots[i], d);
      d.color = pixel(image, dots[i]);
      d.region = r.labels[dots[i]];
    }
  }

  if (!p.strokes) return r;
  const auto order = random_order(n, rng);
  const auto dots = equal_disc_pds(image.width, image.height, 2 * p.alpha_strokes * p.radius_px, order);
  // N per region, then which of its dots take p_i: a random N_pi of them.
  std::vector<std::vector<uint32_t>> members(r.regions.size());
  for (uint32_t idx : dots) members[r.labels[idx]].push_back(idx);
  r.strokes.reserve(dots.size());
  for (size_t k = 0; k < r.regions.size(); ++k) {
    Region& g = r.regions[k];
    auto& mem = members[k];
    g.n = mem.size();
    g.n_pure = g.grey ? g.n : pure_count(g.n, g.mean, g.pure, g.complement, p.weight);
    g.n_complement = g.n - g.n_pure;
    for (size_t i = mem.size(); i > 1; --i) std::swap(mem[i - 1], mem[rng.below(static_cast<uint32_t>(i))]);
    for (size_t i = 0; i < mem.size(); ++i) {
      PaintDot d;
      centre(mem[i], d);
      d.region = static_cast<uint16_t>(k);
      d.complement = i >= g.n_pure;
      const lab::Lab& hue = d.complement ? g.complement : g.pure;
      // L* per dot from the input, as Seurat set lightness with white paint.
      const double L = lab::from_srgb(pixel(image, mem[i])).L;
      d.color = lab::to_srgb({L, hue.a, hue.b});
      r.strokes.push_back(d);
    }
  }
  return r;
}

namespace {

// The ebauche as hatching per colour region: every cell (half a pen width) takes the pen
// of its nearest ebauche circle (the paper counts as a pen: no ink), and the fields are
// hatched a pen each (hatch_pen_fields). O(circles r^2 + cells x pens).
void hatch_ebauche(const std::vector<std::pair<Vec2, size_t>>& circles, size_t n_pens, double radius_mm,
                   const PageTransform& tf, int w, int h, double pen_mm, double coverage, std::vector<Layer>& layers) {
  hatch::PenGrid g;
  g.cell_mm = pen_mm / 2;
  const double cell = g.cell_mm;
  const Vec2 lo = tf.map(0, 0), hi = tf.map(w, h);
  const double x0 = std::min(lo.x, hi.x), y0 = std::min(lo.y, hi.y);
  g.origin_mm = {x0, y0};
  const int W = g.width = std::max(1, static_cast<int>(std::ceil(std::abs(hi.x - lo.x) / cell)));
  const int H = g.height = std::max(1, static_cast<int>(std::ceil(std::abs(hi.y - lo.y) / cell)));
  const size_t n = static_cast<size_t>(W) * static_cast<size_t>(H);
  g.pen.assign(n, hatch::PenGrid::kPaper);
  std::vector<float> best(n, std::numeric_limits<float>::infinity());
  const double rc = radius_mm / cell;
  for (const auto& [c, k] : circles) {
    const double cx = (c.x - x0) / cell, cy = (c.y - y0) / cell;
    const int ylo = std::max(0, static_cast<int>(std::floor(cy - rc))), yhi = std::min(H - 1, static_cast<int>(std::ceil(cy + rc)));
    const int xlo = std::max(0, static_cast<int>(std::floor(cx - rc))), xhi = std::min(W - 1, static_cast<int>(std::ceil(cx + rc)));
    const uint8_t id = k >= n_pens ? hatch::PenGrid::kPaper : static_cast<uint8_t>(k);
    for (int y = ylo; y <= yhi; ++y)
      for (int x = xlo; x <= xhi; ++x) {
        const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
        const float d2 = static_cast<float>(dx * dx + dy * dy);
        const size_t i = static_cast<size_t>(y) * static_cast<size_t>(W) + static_cast<size_t>(x);
        if (d2 <= rc * rc && d2 < best[i]) best[i] = d2, g.pen[i] = id;
      }
  }
  hatch::hatch_pen_fields(g, n_pens, pen_mm, coverage, layers);
}

}  // namespace

Drawing place(const Result& r, const Placement& placement, const std::vector<Pen>& pens, const PlaceOptions& o) {
  const PageTransform tf = placement.transform(r.width, r.height);
  Drawing d;
  d.page.width_mm = tf.page_w();
  d.page.height_mm = tf.page_h();
  d.page.paper = colors::white;
  const double rad = r.radius_px * tf.mm_per_px();
  auto circle = [&](const PaintDot& p, Color fill) {
    Circle c;
    c.c = tf.map(p.x, p.y);
    c.r = rad;
    c.filled = true;
    c.fill = fill;
    return c;
  };
  if (pens.empty()) {
    Layer eb, st;
    eb.pen = Pen{"ebauche", colors::grey, placement.pen_width_mm};
    st.pen = Pen{"divided strokes", colors::grey, placement.pen_width_mm};
    eb.circles.reserve(r.ebauche.size());
    st.circles.reserve(r.strokes.size());
    for (const auto& p : r.ebauche) eb.circles.push_back(circle(p, p.color));
    for (const auto& p : r.strokes) st.circles.push_back(circle(p, p.color));
    if (!eb.circles.empty()) d.layers.push_back(std::move(eb));
    if (!st.circles.empty()) d.layers.push_back(std::move(st));
    return d;
  }
  // The paper is a free "pen": a circle nearer to it than to every ink is left undrawn
  // (white highlights would otherwise become the palette's lightest grey).
  std::vector<Pen> candidates = pens;
  candidates.push_back(Pen{"paper", d.page.paper, 0});
  PenMatcher match(candidates);
  std::vector<Layer> layers(pens.size());
  auto pass = [&](const std::vector<PaintDot>& dots, int pass_index, double share) {
    for (size_t i = 0; i < dots.size(); ++i) {
      if (share < 1 && !in_even_share(i, share)) continue;  // as the budget thins marks
      const PaintDot& p = dots[i];
      const size_t k = match.nearest(p.color);
      if (k == pens.size()) continue;  // the paper
      Circle c = circle(p, pens[k].color);
      c.pass = pass_index;
      layers[k].circles.push_back(c);
    }
  };
  if (o.hatch_ebauche && pens.size() < 255) {  // (pen ids are bytes there)
    std::vector<std::pair<Vec2, size_t>> circles;  // centre, pen (pens.size(): the paper)
    circles.reserve(r.ebauche.size());
    for (const auto& p : r.ebauche) circles.push_back({tf.map(p.x, p.y), match.nearest(p.color)});
    hatch_ebauche(circles, pens.size(), rad, tf, r.width, r.height, placement.pen_width_mm,
                  std::clamp(o.coverage, 1e-3, 1.0), layers);
  } else {
    pass(r.ebauche, 0, 1);
  }
  pass(r.strokes, 1, o.stroke_share);
  for (size_t k = 0; k < pens.size(); ++k) {
    if (layers[k].circles.empty() && layers[k].lines.empty()) continue;
    layers[k].pen = pens[k];
    d.layers.push_back(std::move(layers[k]));
  }
  // Light inks before dark, so a dark pen never drags into a light one's wet ink.
  merge_layers_by_pen(d);
  return d;
}

Drawing pointillism(const Image& image, const Params& params, const Placement& placement,
                    const std::vector<Pen>& pens) {
  return place(paint(image, params), placement, pens);
}

Image region_image(const Result& r) {
  std::vector<Color> colour(r.regions.size());
  for (size_t k = 0; k < r.regions.size(); ++k) colour[k] = lab::to_srgb(r.regions[k].mean);
  Image im;
  im.width = r.width;
  im.height = r.height;
  im.rgb.resize(im.pixels() * 3);
  for (size_t i = 0; i < r.labels.size(); ++i) {
    const Color c = colour[r.labels[i]];
    im.rgb[3 * i] = c.r;
    im.rgb[3 * i + 1] = c.g;
    im.rgb[3 * i + 2] = c.b;
  }
  return im;
}

}  // namespace stipplot::pointillism
