#include "methods/stipple/connect.hpp"

#include "methods/link_rule.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "methods/hatch/hatch_lines.hpp"
#include "plan/tour.hpp"
#include "util/error.hpp"
#include "util/rng.hpp"
#include "util/threads.hpp"

namespace stipplot {

void ConnectParams::validate() const {
  require_range("connect fade", fade, 0, 1);
  require_range("connect min coverage", min_coverage, 1e-4, 1);
  if (relax < 0 || relax > 50) throw UserError("--relax must be an integer in [0, 50], got " + std::to_string(relax));
  require_range("--lift-length", lift_length, 1, 1000);
  require_range("--lift-tone", lift_tone, 0, 1);
  require_range("connect tour seconds", tour_seconds_cap, 0, 3600);
  require_range("connect solid tone", solid_tone, 0.5, 2);
  require_range("connect solid opening", solid_open, 0, 100);
}

double connect_spacing_mm(double u, double pen_mm, const ConnectParams& p) {
  double c = p.fade * std::clamp(u, 0.0, 1.0);
  if (c < p.min_coverage) return std::numeric_limits<double>::infinity();
  if (p.curve && !p.curve->empty()) c = apply_curve(*p.curve, c);
  if (!(c > 0)) return std::numeric_limits<double>::infinity();
  c = std::min(c, 1.0);
  // The ink to lay: the coverage while the lines are apart, more toward full tone, where
  // the path's loops leave gaps between neighbouring lines that only more line closes
  // (SSIM sees the grain of a dark field that is not solid).
  const double ink = c * (1 + kConnectSolid * c * c * c * c);
  return std::max(kConnectInk * pen_mm / ink, 0.4 * pen_mm);
}

namespace {
void require_one_pass(const StippleCanvas& c) {
  if (c.passes.size() != 1 || c.passes[0].ink != StipplePass::Ink::Dark)
    throw UserError(std::string("--connect draws one line with one pen: -m gray, random or negative, not -m ") +
                    to_string(c.method));
}

// Tone (0..1 of the paper to cover, unfaded) of each level of the single pass.
std::array<double, 256> level_tone(const StippleCanvas& c) {
  std::array<double, 256> t{};
  for (int v = 0; v < 256; ++v) t[static_cast<size_t>(v)] = pass_tone(c.passes[0].ink, v);
  return t;
}
}  // namespace

pds::RadiusTable connect_radii(const StippleCanvas& c, const ConnectParams& p) {
  require_one_pass(c);
  p.validate();
  pds::RadiusTable t;
  const double cell = c.grid.cell_mm;
  for (int v = 0; v < 256; ++v) {
    const double r = connect_spacing_mm(pass_tone(c.passes[0].ink, v), c.pen_mm, p) / cell;
    t.r[v] = r;
    t.r2[v] = r * r;
  }
  // Never shrinking toward lighter levels (the visiting order's direction).
  for (int v = 1; v < 256; ++v) {
    if (t.none(static_cast<uint8_t>(v)) || t.none(static_cast<uint8_t>(v - 1))) continue;
    if (t.r[v] < t.r[v - 1]) t.r[v] = t.r[v - 1], t.r2[v] = t.r2[v - 1];
  }
  return t;
}

namespace {
// The spacing in mm at a page point (the largest finite one where its level gets no points).
double spacing_at(const StippleCanvas& c, const pds::RadiusTable& radius, double widest, Vec2 p) {
  const int w = c.grid.image.width, h = c.grid.image.height;
  const int x = std::clamp(static_cast<int>((p.x - c.grid.origin_mm.x) / c.grid.cell_mm), 0, w - 1);
  const int y = std::clamp(static_cast<int>((p.y - c.grid.origin_mm.y) / c.grid.cell_mm), 0, h - 1);
  const uint8_t v = c.planes[c.passes[0].plane][static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)];
  return (radius.none(v) ? widest : radius.r[v]) * c.grid.cell_mm;
}

double tone_at(const StippleCanvas& c, const std::array<double, 256>& tone, Vec2 p) {
  const int w = c.grid.image.width, h = c.grid.image.height;
  const int x = std::clamp(static_cast<int>((p.x - c.grid.origin_mm.x) / c.grid.cell_mm), 0, w - 1);
  const int y = std::clamp(static_cast<int>((p.y - c.grid.origin_mm.y) / c.grid.cell_mm), 0, h - 1);
  return tone[c.planes[c.passes[0].plane][static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)]];
}

double widest_radius(const pds::RadiusTable& r) {
  double m = 0;
  for (int v = 0; v < 256; ++v)
    if (!r.none(static_cast<uint8_t>(v))) m = std::max(m, r.r[v]);
  return m;
}

bool lifted(const StippleCanvas& c, const pds::RadiusTable& radius, double widest, const std::array<double, 256>& tone,
            const ConnectParams& p, Vec2 a, Vec2 b) {
  const double spacing = std::max(spacing_at(c, radius, widest, a), spacing_at(c, radius, widest, b));
  return link_lifted(a, b, spacing, c.grid.cell_mm, p.lift_length, p.lift_tone,
                     [&](Vec2 q) { return tone_at(c, tone, q); });
}
}  // namespace

double connect_solid_pitch_mm(double pen_mm, double fade) { return std::max(0.9 * pen_mm, pen_mm / std::max(fade, 1e-3)); }

namespace {
// Grids of this many cells or more are gone through on every thread.
constexpr size_t kParallelCells = 1'000'000;

// The solid cells opened by a (2h+1)^2 square: kept where such a square wholly inside
// covers them (OpenCV's erosion then dilation; off the grid does not erode, so a field's
// edge at the border stays). Exact on a 0/1 mask; OpenCV runs it on its threads. O(cells x h).
std::vector<uint8_t> open_square(std::vector<uint8_t> cells, int w, int h, int half) {
  cv::Mat m(h, w, CV_8U, cells.data());
  const cv::Mat square = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * half + 1, 2 * half + 1));
  cv::morphologyEx(m, m, cv::MORPH_OPEN, square);
  return cells;
}
}  // namespace

std::vector<uint8_t> connect_solid_cells(const StippleCanvas& c, const ConnectParams& p) {
  require_one_pass(c);
  const int w = c.grid.image.width, h = c.grid.image.height;
  const auto& plane = c.planes[c.passes[0].plane];
  std::vector<uint8_t> solid(plane.size(), 0);
  // Which levels are solid, once; then each cell looks its level up.
  std::array<uint8_t, 256> solid_level{};
  for (int v = 0; v < 256; ++v) solid_level[static_cast<size_t>(v)] = p.fade * pass_tone(c.passes[0].ink, v) >= p.solid_tone;
  bool any = false;
#pragma omp parallel for num_threads(thread_count()) schedule(static) reduction(|| : any) if (plane.size() >= kParallelCells)
  for (long i = 0; i < static_cast<long>(plane.size()); ++i)
    if (solid_level[plane[static_cast<size_t>(i)]]) solid[static_cast<size_t>(i)] = 1, any = true;
  if (!any) return solid;
  const int half = static_cast<int>(std::lround(p.solid_open / c.grid.cell_mm));
  if (half <= 0) return solid;
  return open_square(std::move(solid), w, h, half);
}

bool connect_link_lifted(const StippleCanvas& c, const pds::RadiusTable& radius, const ConnectParams& p, Vec2 a,
                         Vec2 b) {
  require_one_pass(c);
  return lifted(c, radius, widest_radius(radius), level_tone(c), p, a, b);
}

Drawing connect_on_page(const StippleCanvas& c, const ConnectParams& p, ConnectStats* stats) {
  const pds::RadiusTable radius = connect_radii(c, p);
  const int w = c.grid.image.width, h = c.grid.image.height;
  // Solid fields are hatched: their cells get no points (as white paper would).
  const std::vector<uint8_t> solid = connect_solid_cells(c, p);
  std::vector<uint8_t> plane = c.planes[c.passes[0].plane];
  size_t solid_cells = 0;
#pragma omp parallel for num_threads(thread_count()) schedule(static) reduction(+ : solid_cells) if (plane.size() >= kParallelCells)
  for (long i = 0; i < static_cast<long>(plane.size()); ++i)
    if (solid[static_cast<size_t>(i)]) plane[static_cast<size_t>(i)] = 255, ++solid_cells;
  Rng rng(p.seed);
  const auto order = c.method == StippleMethod::Random ? pds::random_order(plane.size(), rng)
                                                       : pds::grayscale_order(plane, rng);
  const std::vector<uint32_t> dots = pds::sample(w, h, plane, radius, order);
  // Continuous positions: jittered within the cell, relaxed toward weighted centroids.
  Rng jitter(p.seed ^ 0x6a09e667f3bcc909ULL);
  const uint32_t gw = static_cast<uint32_t>(w);
  std::vector<Vec2> pos;
  pos.reserve(dots.size());
  for (uint32_t idx : dots) pos.push_back({idx % gw + jitter.uniform(), idx / gw + jitter.uniform()});
  relax_points(pos, plane, radius, w, h, p.relax);
  for (Vec2& q : pos)
    q = c.grid.to_page(std::clamp(q.x, 0.0, static_cast<double>(w)), std::clamp(q.y, 0.0, static_cast<double>(h)));

  Drawing d;
  d.page = c.page;
  Layer layer;
  layer.pen = c.pens.at(0);
  layer.pen.width_mm = c.pen_mm;
  ConnectStats st;
  st.points = pos.size();
  st.solid_cells = solid_cells;
  if (solid_cells > 0) {
    hatch::Mask m{w, h, solid};
    hatch::LineSet set;
    set.angle_deg = 45;
    set.spacing = connect_solid_pitch_mm(c.pen_mm, p.fade) / c.grid.cell_mm;
    set.link = 2.0 / c.grid.cell_mm;
    for (const auto& stroke : hatch::hatch_mask(m, set)) {
      Polyline pl;
      for (const Vec2& q : stroke) pl.pts.push_back(c.grid.to_page(q.x, q.y));
      for (size_t i = 1; i < pl.pts.size(); ++i)
        st.hatch_mm += std::hypot(pl.pts[i].x - pl.pts[i - 1].x, pl.pts[i].y - pl.pts[i - 1].y);
      if (pl.pts.size() >= 2) layer.lines.push_back(std::move(pl)), ++st.lines;
    }
    st.length_mm += st.hatch_mm;
  }
  if (!pos.empty()) {
    plan::TourOptions to;
    to.seconds_cap = p.tour_seconds_cap;
    to.seed = p.seed;
    const std::vector<int32_t> partner(pos.size(), -1);
    const std::vector<uint32_t> path = plan::plan_tour(pos, partner, c.grid.origin_mm, to);
    const double widest = widest_radius(radius);
    const auto tone = level_tone(c);
    Polyline run{{pos[path[0]]}};
    auto flush = [&] {
      if (run.pts.size() == 1) {
        layer.dots.push_back({run.pts[0], c.pen_mm});
        ++st.touches;
      } else {
        for (size_t i = 1; i < run.pts.size(); ++i)
          st.length_mm += std::hypot(run.pts[i].x - run.pts[i - 1].x, run.pts[i].y - run.pts[i - 1].y);
        layer.lines.push_back(std::move(run));
        ++st.lines;
      }
      run.pts.clear();
    };
    // Each link's lift on every thread (each reads the grid alone), then the runs in order.
    std::vector<uint8_t> lift(path.size(), 0);
#pragma omp parallel for num_threads(thread_count()) schedule(dynamic, 4096) if (path.size() >= 20'000)
    for (long i = 1; i < static_cast<long>(path.size()); ++i)
      lift[static_cast<size_t>(i)] = lifted(c, radius, widest, tone, p, pos[path[static_cast<size_t>(i) - 1]], pos[path[static_cast<size_t>(i)]]);
    for (size_t i = 1; i < path.size(); ++i) {
      const Vec2 b = pos[path[i]];
      if (lift[i]) {
        ++st.lifted;
        flush();
      } else {
        ++st.links;
      }
      run.pts.push_back(b);
    }
    flush();
  }
  d.layers.push_back(std::move(layer));
  if (stats) *stats = st;
  return d;
}

LevelCoverage measured_line_coverage(const StippleCanvas& c, const Drawing& d) {
  require_one_pass(c);
  const int w = c.grid.image.width, h = c.grid.image.height;
  const int S = 2;  // raster cells a grid cell, each way
  const int rw = w * S, rh = h * S;
  const double px = c.grid.cell_mm / S;
  auto to_raster = [&](Vec2 q) { return Vec2{(q.x - c.grid.origin_mm.x) / px, (q.y - c.grid.origin_mm.y) / px}; };
  // Every mark as a capsule in raster cells: a segment a-b and a radius.
  struct Capsule {
    Vec2 a, b;
    double r;
  };
  std::vector<Capsule> caps;
  for (const Layer& l : d.layers) {
    const double r = 0.5 * l.pen.width_mm / px;
    for (const Polyline& pl : l.lines)
      for (size_t i = 1; i < pl.pts.size(); ++i) caps.push_back({to_raster(pl.pts[i - 1]), to_raster(pl.pts[i]), r});
    for (const Dot& dot : l.dots) {
      const Vec2 q = to_raster(dot.c);
      caps.push_back({q, q, 0.5 * std::max(dot.diameter, l.pen.width_mm) / px});
    }
  }
  // Bands of rows, each painted and counted on its own (a cell is inked by any capsule
  // over it, whichever paints it; the counts are whole numbers): the same on any thread
  // count.
  constexpr int kBandRows = 64;
  const int bands = (rh + kBandRows - 1) / kBandRows;
  std::vector<LevelCoverage> per_band(static_cast<size_t>(bands));
  const auto& plane = c.planes[c.passes[0].plane];
#pragma omp parallel num_threads(thread_count()) if (static_cast<size_t>(rw) * static_cast<size_t>(rh) >= kParallelCells)
  {
    std::vector<uint8_t> ink;
#pragma omp for schedule(dynamic, 1)
    for (int band = 0; band < bands; ++band) {
      const int by0 = band * kBandRows, by1 = std::min(rh, by0 + kBandRows);  // rows [by0, by1)
      ink.assign(static_cast<size_t>(by1 - by0) * static_cast<size_t>(rw), 0);
      for (const Capsule& cap : caps) {
        const Vec2 a = cap.a, b = cap.b;
        const double r = cap.r;
        const int y0 = std::max(by0, static_cast<int>(std::floor(std::min(a.y, b.y) - r))),
                  y1 = std::min(by1 - 1, static_cast<int>(std::ceil(std::max(a.y, b.y) + r)));
        if (y0 > y1) continue;
        const int x0 = std::max(0, static_cast<int>(std::floor(std::min(a.x, b.x) - r))),
                  x1 = std::min(rw - 1, static_cast<int>(std::ceil(std::max(a.x, b.x) + r)));
        // Every raster cell whose centre lies within r of the segment a-b.
        const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy, r2 = r * r;
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) {
            const double qx = x + 0.5 - a.x, qy = y + 0.5 - a.y;
            const double t = l2 > 0 ? std::clamp((qx * dx + qy * dy) / l2, 0.0, 1.0) : 0;
            const double ex = qx - t * dx, ey = qy - t * dy;
            if (ex * ex + ey * ey <= r2) ink[static_cast<size_t>(y - by0) * static_cast<size_t>(rw) + static_cast<size_t>(x)] = 1;
          }
      }
      std::array<uint64_t, 256> cells{}, covered{};
      for (int y = by0; y < by1; ++y)
        for (int x = 0; x < rw; ++x) {
          const uint8_t v = plane[static_cast<size_t>(y / S) * static_cast<size_t>(w) + static_cast<size_t>(x / S)];
          cells[v] += 1;
          covered[v] += ink[static_cast<size_t>(y - by0) * static_cast<size_t>(rw) + static_cast<size_t>(x)];
        }
      for (size_t v = 0; v < 256; ++v)
        per_band[static_cast<size_t>(band)].cells[v] = static_cast<double>(cells[v]),
                                    per_band[static_cast<size_t>(band)].covered[v] = static_cast<double>(covered[v]);
    }
  }
  LevelCoverage out;
  for (const LevelCoverage& band : per_band)
    for (size_t v = 0; v < 256; ++v) out.cells[v] += band.cells[v], out.covered[v] += band.covered[v];
  return out;
}

}  // namespace stipplot
