#include "methods/tree/tree.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "eval/bounded_blur.hpp"
#include "methods/stipple/pds.hpp"
#include "methods/tree/trails.hpp"
#include "util/error.hpp"
#include "util/rng.hpp"

namespace stipplot::tree {

namespace {
double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

Variant parse_variant(const std::string& name) {
  static const struct {
    const char* name;
    bool cross;
    std::vector<Distance> layers;
  } table[] = {
      {"ed", false, {Distance::ED}},          {"bd", false, {Distance::BD}},
      {"sibd", false, {Distance::SIBD}},      {"bd+sibd", false, {Distance::BD, Distance::SIBD}},
      {"ced", true, {Distance::ED}},          {"cbd", true, {Distance::BD}},
      {"csibd", true, {Distance::SIBD}},      {"cbd+csibd", true, {Distance::BD, Distance::SIBD}},
  };
  for (const auto& v : table)
    if (name == v.name) return Variant{v.name, v.cross, v.layers};
  throw UserError("--distance: unknown distance '" + name +
                  "' (use ed, bd, sibd, bd+sibd, or the cross variants ced, cbd, csibd, cbd+csibd)");
}

void TreeParams::validate() const {
  require_range("-a", a, 0, 500);
  require_range("-b", b, 0, 500);
  if (tone_law && !(a > 0)) throw UserError("-a must be > 0 with --law tone (the darkest level's spacing)");
  require_range("--alpha-bd", alpha_bd, 0, 1e6);
  require_range("--alpha-sibd", alpha_sibd, 0, 1e6);
  require_range("--h", h, 0, 1e9);
  require_range("--sigma", sigma, 0, 100);
  require_range("--dt-gain", dt_gain, 0, 1e4);
  edges.validate();  // checked even when unused: a bad option is an error, never ignored
}

void TerrainParams::validate() const {
  require_range("--valley-depth", valley_depth, 0, 1e4);
  require_range("--relief", relief, 0, 1e3);
  require_range("--light-azimuth", azimuth, -360, 360);
  require_range("--light-elevation", elevation, 1, 90);
}

double mean_abs_cos_to_gradient(const PointSet& pts, const std::vector<Edge>& edges, const std::vector<float>& field,
                                int width, int height, double min_gradient, size_t* measured) {
  double sum = 0;
  size_t count = 0;
  auto at = [&](int x, int y) {
    x = std::clamp(x, 0, width - 1), y = std::clamp(y, 0, height - 1);
    return double(field[static_cast<size_t>(y) * width + x]);
  };
  for (const Edge& e : edges) {
    const double ex = double(pts.x[e.b]) - pts.x[e.a], ey = double(pts.y[e.b]) - pts.y[e.a];
    const double len = std::hypot(ex, ey);
    if (len == 0) continue;
    const int mx = static_cast<int>(std::lround((pts.x[e.a] + pts.x[e.b]) / 2));
    const int my = static_cast<int>(std::lround((pts.y[e.a] + pts.y[e.b]) / 2));
    // Sobel, scaled to units per pixel.
    const double gx = ((at(mx + 1, my - 1) + 2 * at(mx + 1, my) + at(mx + 1, my + 1)) -
                       (at(mx - 1, my - 1) + 2 * at(mx - 1, my) + at(mx - 1, my + 1))) / 8;
    const double gy = ((at(mx - 1, my + 1) + 2 * at(mx, my + 1) + at(mx + 1, my + 1)) -
                       (at(mx - 1, my - 1) + 2 * at(mx, my - 1) + at(mx + 1, my - 1))) / 8;
    const double g = std::hypot(gx, gy);
    if (g < min_gradient) continue;
    sum += std::abs(ex * gx + ey * gy) / (len * g);
    ++count;
  }
  if (measured) *measured = count;
  return count ? sum / double(count) : 0;
}

TreeResult tree_pixels(const Image& image, const TreeParams& p) {
  p.validate();
  if (image.pixels() == 0) throw UserError("image has no pixels");
  if (image.pixels() >= (1ull << 31)) throw UserError("image too large for the tree method (2 Gpixel limit)");
  const int w = image.width, h = image.height;
  const size_t n = image.pixels();
  TreeResult r;
  r.width = w, r.height = h, r.cross = p.variant.cross;
  r.grey = image.luma();

  auto t0 = std::chrono::steady_clock::now();
  Rng rng(p.seed);
  const auto order = pds::grayscale_order(r.grey, rng);
  const pds::RadiusTable radius = p.tone_law ? pds::RadiusTable::tone(p.a, p.b) : pds::RadiusTable::linear(p.a, p.b, false);
  const auto dots = pds::sample(w, h, r.grey, radius, order);
  r.seconds_points = since(t0);

  t0 = std::chrono::steady_clock::now();
  r.field.resize(n);
  // Gradients below this are too flat to give an edge a direction: one grey level per
  // px for the image; for the edge distance (slope 1 px/px but on its ridges) half its gain.
  double gain = 1, min_gradient = 1;
  if (!p.variant.cross) {
    // BD's d: the input slightly blurred (§4.2), so single noisy pixels do not
    // decide which way a line runs.
    cv::Mat g(h, w, CV_8U, r.grey.data()), f, out(h, w, CV_32F, r.field.data());
    g.convertTo(f, CV_32F);
    if (p.sigma > 0)
      gaussian_blur_rows(f, out, p.sigma, cv::BORDER_REPLICATE);
    else
      f.copyTo(out);
  } else {
    r.edge_mask = major_edges(image, p.edges);
    r.edge_dt = distance_from(r.edge_mask, w, h);
    float mx = 0;
    for (float v : r.edge_dt) mx = std::max(mx, v);
    // As displayed in the paper's Fig. 9(c, d): the distance scaled to grey levels.
    gain = p.dt_gain > 0 ? p.dt_gain : (mx > 0 ? 255.0 / mx : 1.0);
    for (size_t i = 0; i < n; ++i) r.field[i] = static_cast<float>(gain * r.edge_dt[i]);
    min_gradient = 0.5 * gain;
  }
  r.seconds_edges = since(t0);

  std::vector<uint8_t> taken(n, 0);
  for (uint32_t i : dots) {
    r.points.push(float(i % w), float(i / w), r.field[i]);
    taken[i] = 1;
  }
  r.stipple_count = r.points.size();
  if (p.variant.cross) {
    // §6.2: every edge pixel joins the points.
    for (size_t i = 0; i < n; ++i)
      if (r.edge_mask[i] && !taken[i]) r.points.push(float(i % w), float(i / w), r.field[i]);
  }

  // The O(n²) reference is for comparison; past this it would run for many minutes.
  constexpr size_t kMaxPrimPoints = 200'000;
  if (p.reference_prim && r.points.size() > kMaxPrimPoints)
    throw UserError("--reference-prim: " + std::to_string(r.points.size()) + " points is too many for the O(n^2) Prim (at most " +
                    std::to_string(kMaxPrimPoints) + "); drop it to use the fast exact MST");
  t0 = std::chrono::steady_clock::now();
  for (Distance kind : p.variant.layers) {
    CostParams c;
    c.kind = kind;
    c.alpha = kind == Distance::SIBD ? p.alpha_sibd : p.alpha_bd;
    c.h = p.h;
    TreeLayer layer{kind, p.reference_prim ? mst_prim_reference(r.points, c) : mst_exact(r.points, c), 0, 0, 0};
    if (p.tone_law) {
      // A spanning tree must reach every point, so it crosses the ground the law leaves
      // empty; the pen need not.
      auto at = [&](uint32_t i) {
        return radius.r[r.grey[static_cast<size_t>(r.points.y[i]) * w + static_cast<size_t>(r.points.x[i])]];
      };
      const size_t before = layer.edges.size();
      std::erase_if(layer.edges, [&](const Edge& e) {
        const double dx = double(r.points.x[e.a]) - r.points.x[e.b], dy = double(r.points.y[e.a]) - r.points.y[e.b];
        const double reach = kBridge * std::max(at(e.a), at(e.b));
        return dx * dx + dy * dy > reach * reach;
      });
      layer.bridges = before - layer.edges.size();
    }
    layer.mean_abs_cos = mean_abs_cos_to_gradient(r.points, layer.edges, r.field, w, h, min_gradient, &layer.measured);
    r.layers.push_back(std::move(layer));
  }
  r.seconds_mst = since(t0);
  return r;
}

double crowd_gap_mm(size_t lines, double pen_mm, double disc_mm, double coverage) {
  const double R = disc_mm / 2;
  const double allowed = coverage * M_PI * R * R / static_cast<double>(std::max<size_t>(lines, 1));
  // Per line: pen x (R - gap) <= allowed (the round ends overlap the lines at the point).
  return std::clamp(R - allowed / pen_mm, 0.0, R);
}

Drawing place_tree(const TreeResult& r, const Placement& placement, const TreeStrokes& strokes) {
  const PageTransform tf = placement.transform(r.width, r.height);
  const double pen = placement.pen_width_mm;
  Drawing d;
  d.page.width_mm = tf.page_w();
  d.page.height_mm = tf.page_h();
  const size_t n = r.points.x.size();
  std::vector<uint32_t> degree(n);
  const bool outline = strokes.link && strokes.weight > 1;
  for (const TreeLayer& tl : r.layers) {
    Layer layer;
    layer.pen = Pen{std::string(r.cross ? "tree-c" : "tree-") + to_string(tl.kind), colors::black, pen};
    // Linked: the points' positions, then (trails) one vertex of its own for every
    // segment end that stops short of a crowded point (the trail ends there).
    std::vector<Vec2> pos;
    std::vector<TrailEdge> trail_edges;
    if (strokes.link) {
      pos.reserve(n);
      for (size_t i = 0; i < n; ++i) pos.push_back(tf.map(r.points.x[i] + 0.5, r.points.y[i] + 0.5));
    }
    if (outline) {  // no crowd gaps: the loop passes round every point
      trail_edges.reserve(tl.edges.size());
      for (const Edge& e : tl.edges) trail_edges.push_back({e.a, e.b});
      layer.lines = forest_outlines(pos, trail_edges, (strokes.weight - 1) * pen / 2);
      d.layers.push_back(std::move(layer));
      continue;
    }
    layer.lines.reserve(tl.edges.size());
    std::fill(degree.begin(), degree.end(), 0);
    for (const Edge& e : tl.edges) ++degree[e.a], ++degree[e.b];
    for (const Edge& e : tl.edges) {
      Vec2 a = tf.map(r.points.x[e.a] + 0.5, r.points.y[e.a] + 0.5);
      Vec2 b = tf.map(r.points.x[e.b] + 0.5, r.points.y[e.b] + 0.5);
      const double len = std::hypot(b.x - a.x, b.y - a.y);
      double ga = 0, gb = 0;
      if (len > 0) {
        ga = std::min(crowd_gap_mm(degree[e.a], pen), kCrowdMaxShare * len);
        gb = std::min(crowd_gap_mm(degree[e.b], pen), kCrowdMaxShare * len);
        const Vec2 u{(b.x - a.x) / len, (b.y - a.y) / len};
        a = {a.x + u.x * ga, a.y + u.y * ga};
        b = {b.x - u.x * gb, b.y - u.y * gb};
      }
      if (!strokes.link) {
        layer.lines.push_back(Polyline{{a, b}});
        continue;
      }
      TrailEdge te{e.a, e.b};
      if (ga > 0) te.a = static_cast<uint32_t>(pos.size()), pos.push_back(a);
      if (gb > 0) te.b = static_cast<uint32_t>(pos.size()), pos.push_back(b);
      trail_edges.push_back(te);
    }
    if (strokes.link) {
      const TrailPlan tp = forest_trails(pos, trail_edges, strokes.retrace_mm);
      for (const auto& trail : tp.trails) {
        Polyline pl;
        pl.pts.reserve(trail.size());
        for (uint32_t v : trail) pl.pts.push_back(pos[v]);
        layer.lines.push_back(std::move(pl));
      }
    }
    d.layers.push_back(std::move(layer));
  }
  return d;
}

Drawing tree_drawing(const Image& image, const TreeParams& params, const Placement& placement, const TreeStrokes& strokes) {
  placement.validate();
  return place_tree(tree_pixels(image, params), placement, strokes);
}

}  // namespace stipplot::tree
