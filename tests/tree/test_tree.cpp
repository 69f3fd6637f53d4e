// Dendritic drawings (seed 002): exactness of the fast MST against the paper's Prim,
// the direction claims, terrain maps, and rejection of bad parameters.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>

#include "methods/tree/tree.hpp"
#include "cli_json.hpp"
#include "test_util.hpp"
#include "util/error.hpp"
#include "util/rng.hpp"
#include "util/threads.hpp"

using namespace stipplot;
using namespace stipplot::tree;

namespace {

void require_same_weight(const PointSet& pts, const CostParams& c) {
  const auto ref = mst_prim_reference(pts, c);
  const auto fast = mst_exact(pts, c);
  REQUIRE(test::spans(ref, pts.size()));
  REQUIRE(test::spans(fast, pts.size()));
  const double a = total_cost(ref), b = total_cost(fast);
  INFO("n=" << pts.size() << " cost=" << to_string(c.kind) << " alpha=" << c.alpha << " h=" << c.h);
  REQUIRE(b == Approx(a).epsilon(1e-12).margin(1e-9));
  // Each edge's stored cost is the true cost of that pair.
  for (const Edge& e : fast) REQUIRE(e.cost == Approx(std::sqrt(edge_cost2(pts, c, e.a, e.b))).epsilon(1e-12));
}

Image image_from(int w, int h, const std::function<double(int, int)>& grey) {
  std::vector<uint8_t> g(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) g[size_t(y) * w + x] = uint8_t(std::clamp(std::lround(grey(x, y)), 0L, 255L));
  return Image::from_grey(w, h, g);
}

Image shared_image(const std::string& name, int max_side) {
  Image img = load_image(std::string(STIPPLOT_SHARED_DIR) + "/images/" + name);
  const double s = double(max_side) / std::max(img.width, img.height);
  const int w = std::max(1, int(img.width * s)), h = std::max(1, int(img.height * s));
  cv::Mat src(img.height, img.width, CV_8UC3, img.rgb.data()), dst;
  cv::resize(src, dst, cv::Size(w, h), 0, 0, cv::INTER_AREA);
  Image out;
  out.width = w, out.height = h;
  out.rgb.assign(dst.data, dst.data + size_t(w) * h * 3);
  return out;
}

// A smooth radial gradient: dark in the centre, bright at the rim.
Image radial(int size) {
  const double c = (size - 1) / 2.0;
  return image_from(size, size, [&](int x, int y) { return 20 + 220 * std::hypot(x - c, y - c) / (c * std::sqrt(2.0)); });
}

// Runs `stipplot tree ARGS`; returns its stderr.
std::string run_cli(const std::string& args, int* status) {
  const test::RunResult r = test::run_cli("tree " + args);
  *status = r.exit_code;
  return r.err;
}

}  // namespace

TEST_CASE("fast MST equals Prim's weight on random point sets", "[tree][mst]") {
  Rng rng(42);
  for (int trial = 0; trial < 60; ++trial) {
    const size_t n = 2 + rng.below(400);
    PointSet pts;
    // Integer coordinates on a small grid make many equal costs (ties); some trials
    // use real coordinates and clustered intensities.
    const bool integer = trial % 2 == 0;
    const int side = 10 + int(rng.below(120));
    for (size_t i = 0; i < n; ++i) {
      float x = integer ? float(rng.below(uint32_t(side))) : float(rng.uniform() * side);
      float y = integer ? float(rng.below(uint32_t(side))) : float(rng.uniform() * side);
      float d = trial % 3 == 0 ? float(rng.below(4) * 60) : float(rng.uniform() * 255);
      pts.push(x, y, d);
    }
    for (Distance kind : {Distance::ED, Distance::BD, Distance::SIBD}) {
      CostParams c;
      c.kind = kind;
      c.alpha = trial % 4 == 0 ? 0.0 : rng.uniform() * 3;
      c.h = trial % 5 == 0 ? 0.0 : rng.uniform() * 2000;
      require_same_weight(pts, c);
    }
  }
}

TEST_CASE("fast MST handles degenerate inputs", "[tree][mst]") {
  PointSet empty;
  CostParams c;
  REQUIRE(mst_exact(empty, c).empty());
  PointSet one;
  one.push(3, 4, 5);
  REQUIRE(mst_exact(one, c).empty());
  PointSet same;  // every point identical: all costs zero
  for (int i = 0; i < 50; ++i) same.push(7, 7, 100);
  for (Distance k : {Distance::ED, Distance::BD, Distance::SIBD}) {
    c.kind = k;
    require_same_weight(same, c);
  }
  PointSet line;  // collinear, equally spaced: every tree edge ties
  for (int i = 0; i < 300; ++i) line.push(float(i), 0, float(i % 7) * 30);
  for (Distance k : {Distance::ED, Distance::BD, Distance::SIBD}) {
    c.kind = k;
    require_same_weight(line, c);
  }
}

TEST_CASE("fast MST is the same tree edge for edge on 1 and 3 threads, ties and all", "[tree][mst][threads]") {
  // Above the size where the searches go to threads; integer coordinates make many equal
  // costs, which the tie order must settle the same whoever searches first.
  Rng rng(7);
  for (const bool integer : {true, false}) {
    PointSet pts;
    for (int i = 0; i < 40000; ++i) {
      const float x = integer ? float(rng.below(300)) : float(rng.uniform() * 300);
      const float y = integer ? float(rng.below(300)) : float(rng.uniform() * 300);
      pts.push(x, y, integer ? float(rng.below(4) * 60) : float(rng.uniform() * 255));
    }
    for (Distance kind : {Distance::ED, Distance::BD, Distance::SIBD}) {
      CostParams c;
      c.kind = kind;
      c.alpha = 0.7;
      c.h = 500;
      set_thread_count(1);
      const auto one = mst_exact(pts, c);
      set_thread_count(3);
      const auto three = mst_exact(pts, c);
      set_thread_count(0);
      INFO("integer=" << integer << " cost=" << to_string(kind));
      REQUIRE(one.size() == pts.size() - 1);
      REQUIRE(three.size() == one.size());
      bool same = true;
      for (size_t k = 0; k < one.size(); ++k)
        same = same && one[k].a == three[k].a && one[k].b == three[k].b && one[k].cost == three[k].cost;
      CHECK(same);
    }
  }
}

TEST_CASE("fast MST equals Prim's weight on stipples of the sample images, every variant", "[tree][mst]") {
  for (const char* name : {"coffee.png", "horse.png", "text.png", "rocket.jpg", "hubble_deep_field.jpg", "starry_night.jpg"}) {
    const Image img = shared_image(name, 140);
    for (const char* v : {"ed", "bd", "sibd", "cbd", "csibd"}) {
      TreeParams p;
      p.variant = parse_variant(v);
      p.edges.min_length = 10;
      TreeResult fast = tree_pixels(img, p);
      p.reference_prim = true;
      TreeResult ref = tree_pixels(img, p);
      INFO(name << " " << v << " points=" << fast.points.size());
      REQUIRE(fast.points.size() == ref.points.size());
      REQUIRE(fast.points.size() > 100);
      REQUIRE(test::spans(fast.layers[0].edges, fast.points.size()));
      REQUIRE(total_cost(fast.layers[0].edges) == Approx(total_cost(ref.layers[0].edges)).epsilon(1e-12));
    }
  }
}

TEST_CASE("direction claims on a smooth radial gradient: BD along iso-lines, SIBD along the gradient, ED neither",
          "[tree][claims]") {
  const Image img = radial(300);
  TreeParams p;
  p.variant = parse_variant("bd+sibd");
  const TreeResult r = tree_pixels(img, p);
  REQUIRE(r.layers.size() == 2);
  p.variant = parse_variant("ed");
  const TreeResult e = tree_pixels(img, p);
  const double bd = r.layers[0].mean_abs_cos, sibd = r.layers[1].mean_abs_cos, ed = e.layers[0].mean_abs_cos;
  WARN("mean |cos(edge, gradient)| on a radial gradient: ED " << ed << ", BD " << bd << ", SIBD " << sibd << " (uniform = "
                                                               << 2 / M_PI << ")");
  REQUIRE(r.layers[0].measured > r.layers[0].edges.size() / 2);
  REQUIRE(r.layers[1].measured > r.layers[1].edges.size() / 2);
  // The paper's stipples are denser where darker; on this gradient that alone tilts ED
  // edges a little toward the gradient, so the anisotropic trees are judged against ED.
  CHECK(bd < 0.5);
  CHECK(bd < ed - 0.15);
  CHECK(sibd > 0.85);
  CHECK(sibd > ed + 0.15);
  // ED: no preferred direction in the image frame: four 45° bins of edge angle each
  // hold about a quarter of the edges.
  double bins[4] = {0, 0, 0, 0};
  for (const Edge& ed_edge : e.layers[0].edges) {
    double a = std::atan2(e.points.y[ed_edge.b] - e.points.y[ed_edge.a], e.points.x[ed_edge.b] - e.points.x[ed_edge.a]);
    if (a < 0) a += M_PI;
    bins[std::min(3, int(a / (M_PI / 4)))] += 1;
  }
  for (double b : bins) CHECK(b / double(e.layers[0].edges.size()) == Approx(0.25).margin(0.07));

  // Grayscale-order stipples are laid ring by ring on this image, which tilts ED a
  // little toward the gradient. On uniformly random points only the distance orders
  // the edges: ED matches random directions (mean |cos| = 2/π), BD and SIBD do not.
  Rng rng(7);
  PointSet pts;
  std::vector<float> field(300 * 300);
  for (int y = 0; y < 300; ++y)
    for (int x = 0; x < 300; ++x) field[size_t(y) * 300 + x] = float(img.channel(x, y, 0));
  for (int i = 0; i < 4000; ++i) {
    const float x = float(rng.uniform() * 299), y = float(rng.uniform() * 299);
    pts.push(x, y, field[size_t(std::lround(y)) * 300 + size_t(std::lround(x))]);
  }
  double m[3];
  for (int k = 0; k < 3; ++k) {
    CostParams c;
    c.kind = k == 0 ? Distance::ED : (k == 1 ? Distance::BD : Distance::SIBD);
    c.alpha = k == 2 ? 0.5 : 1;
    m[k] = mean_abs_cos_to_gradient(pts, mst_exact(pts, c), field, 300, 300, 1.0);
  }
  WARN("uniform random points: ED " << m[0] << ", BD " << m[1] << ", SIBD " << m[2]);
  CHECK(std::abs(m[0] - 2 / M_PI) < 0.03);
  CHECK(m[1] < m[0] - 0.05);
  CHECK(m[2] > m[0] + 0.05);
}

TEST_CASE("cross variants: edges join the points, CBD runs along edges, CSIBD across them", "[tree][claims]") {
  // A bright disc on a dark ground: one circular major edge.
  const Image img = image_from(240, 240, [](int x, int y) { return std::hypot(x - 120, y - 120) < 70 ? 220 : 40; });
  TreeParams p;
  p.variant = parse_variant("cbd+csibd");
  const TreeResult r = tree_pixels(img, p);
  size_t on_edge = 0;
  for (uint8_t m : r.edge_mask) on_edge += m != 0;
  REQUIRE(on_edge > 300);                 // about the circumference, 2π·70 ≈ 440
  REQUIRE(on_edge < 1200);
  REQUIRE(r.points.size() > r.stipple_count);  // edge pixels joined the stipples
  const double cbd = r.layers[0].mean_abs_cos, csibd = r.layers[1].mean_abs_cos;
  WARN("mean |cos(edge, edge-distance gradient)|: CBD " << cbd << ", CSIBD " << csibd);
  CHECK(cbd < 0.45);
  CHECK(csibd > 0.7);
}

TEST_CASE("major edges drop short chains", "[tree][edges]") {
  // A long bar edge and a tiny speck: the speck's edge chain is shorter than the limit.
  const Image img = image_from(200, 120, [](int x, int y) {
    if (y > 40 && y < 80 && x > 20 && x < 180) return 230;
    if (x > 10 && x < 14 && y > 100 && y < 104) return 230;
    return 30;
  });
  EdgeParams e;
  e.min_length = 40;
  auto mask = major_edges(img, e);
  size_t speck = 0, bar = 0;
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 200; ++x) {
      if (!mask[size_t(y) * 200 + x]) continue;
      (y > 92 ? speck : bar) += 1;
    }
  CHECK(speck == 0);
  CHECK(bar > 300);
  e.min_length = 0;
  mask = major_edges(img, e);
  speck = 0;
  for (int y = 93; y < 120; ++y)
    for (int x = 0; x < 200; ++x) speck += mask[size_t(y) * 200 + x] != 0;
  CHECK(speck > 0);
}

TEST_CASE("tree drawing: one 2-point polyline per tree edge, one layer per tree, deterministic", "[tree][drawing]") {
  const Image img = shared_image("horse.png", 160);
  TreeParams p;
  p.variant = parse_variant("bd+sibd");
  Placement place;
  const TreeResult r = tree_pixels(img, p);
  const Drawing d = place_tree(r, place);
  REQUIRE(d.layers.size() == 2);
  for (const Layer& l : d.layers) {
    REQUIRE(l.lines.size() == r.points.size() - 1);
    REQUIRE(l.dots.empty());
    for (const Polyline& pl : l.lines) {
      REQUIRE(pl.pts.size() == 2);
      REQUIRE(pl.pts[0].x >= place.margin_mm - 1e-9);
      REQUIRE(pl.pts[0].x <= d.page.width_mm - place.margin_mm + 1e-9);
    }
  }
  const Drawing again = tree_drawing(img, p, place);
  REQUIRE(again.layers[1].lines.size() == d.layers[1].lines.size());
  for (size_t i = 0; i < d.layers[1].lines.size(); ++i) REQUIRE(again.layers[1].lines[i].pts == d.layers[1].lines[i].pts);
}

TEST_CASE("the tone law: lines' ink follows the darkness, light ground stays empty, no edge bridges it", "[tree][tone]") {
  // Black on the left, white between, mid grey (darkness 0.5) on the right.
  const Image img = image_from(300, 130, [](int x, int) { return x < 120 ? 0 : x < 180 ? 255 : 127.5; });
  TreeParams p;
  p.variant = parse_variant("ed");
  p.tone_law = true;
  const TreeResult r = tree_pixels(img, p);
  const auto& edges = r.layers.at(0).edges;
  for (size_t i = 0; i < r.points.size(); ++i) CHECK(!(r.points.x[i] >= 120 && r.points.x[i] < 180));
  CHECK(r.layers[0].bridges >= 1);  // the tree's crossing of the white band is not drawn
  double ink[2] = {0, 0};
  for (const Edge& e : edges) {
    const double ax = r.points.x[e.a], bx = r.points.x[e.b];
    const double len = std::hypot(bx - ax, double(r.points.y[e.b]) - r.points.y[e.a]);
    CHECK(len <= kBridge * (p.a + p.b) + 1e-9);
    REQUIRE((ax < 120) == (bx < 120));  // nothing joins the two fields
    ink[ax < 120 ? 0 : 1] += len;
  }
  // Line per area a / t apart goes as t: the black field twice the grey one's (the paper's
  // linear law, r = a + b d / 255, gives it 3 times: 2 px against 6 px apart).
  const double ratio = (ink[0] / 120) / (ink[1] / 120);
  INFO("line per area, black / grey: " << ratio);
  CHECK(ratio > 1.6);
  CHECK(ratio < 2.3);
  p.tone_law = false;
  const TreeResult paper = tree_pixels(img, p);
  CHECK(paper.layers[0].edges.size() == paper.points.size() - 1);  // the paper's tree spans everything
  CHECK(paper.layers[0].bridges == 0);
}

TEST_CASE("terrain: image size, bright ground red, dark ground green, edges blue", "[tree][terrain]") {
  // Left half dark, right half bright.
  const Image img = image_from(160, 100, [](int x, int) { return x < 80 ? 40 : 215; });
  TreeParams p;
  p.variant = parse_variant("sibd");
  const TreeResult r = tree_pixels(img, p);
  TerrainParams t;
  const Image land = terrain(r, t);
  REQUIRE(land.width == 160);
  REQUIRE(land.height == 100);
  REQUIRE(land.rgb.size() == size_t(160) * 100 * 3);
  double left[3] = {0, 0, 0}, right[3] = {0, 0, 0};
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 160; ++x)
      for (int c = 0; c < 3; ++c) (x < 70 ? left : (x >= 90 ? right : left))[c] += x >= 70 && x < 90 ? 0 : land.channel(x, y, c);
  CHECK(left[1] > 1.5 * left[0]);   // green lowland
  CHECK(right[0] > 1.5 * right[1]); // red highland
  // Valleys shade: the terrain is not flat colour.
  std::vector<int> greens;
  for (int x = 5; x < 65; ++x) greens.push_back(land.channel(x, 50, 1));
  CHECK(*std::max_element(greens.begin(), greens.end()) - *std::min_element(greens.begin(), greens.end()) > 20);

  // Cross variant: the major edge is drawn blue.
  const Image disc = image_from(200, 200, [](int x, int y) { return std::hypot(x - 100, y - 100) < 60 ? 220 : 40; });
  p.variant = parse_variant("csibd");
  const TreeResult rc = tree_pixels(disc, p);
  const Image landc = terrain(rc, t);
  REQUIRE(landc.width == 200);
  size_t blue = 0, edge = 0;
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x) {
      if (!rc.edge_mask[size_t(y) * 200 + x]) continue;
      ++edge;
      blue += landc.channel(x, y, 2) > landc.channel(x, y, 0) && landc.channel(x, y, 2) > landc.channel(x, y, 1);
    }
  REQUIRE(edge > 200);
  CHECK(blue == edge);
}

TEST_CASE("bad tree parameters are rejected naming the parameter", "[tree][errors]") {
  const Image img = radial(40);
  auto rejects = [&](auto set, const char* name) {
    TreeParams p;
    set(p);
    try {
      tree_pixels(img, p);
      FAIL("accepted a bad " << name);
    } catch (const UserError& e) {
      REQUIRE(std::string(e.what()).find(name) != std::string::npos);
    }
  };
  rejects([](TreeParams& p) { p.alpha_bd = -1; }, "--alpha-bd");
  rejects([](TreeParams& p) { p.alpha_sibd = std::nan(""); }, "--alpha-sibd");
  rejects([](TreeParams& p) { p.h = -300; }, "--h");
  rejects([](TreeParams& p) { p.sigma = -0.5; }, "--sigma");
  rejects([](TreeParams& p) { p.sigma = INFINITY; }, "--sigma");
  rejects([](TreeParams& p) { p.a = -2; }, "-a");
  rejects([](TreeParams& p) {
    p.tone_law = true;
    p.a = 0;
  }, "-a");
  rejects([](TreeParams& p) {
    p.variant = parse_variant("csibd");
    p.edges.spatial_radius = -1;
  }, "--ms-spatial");
  TerrainParams t;
  t.valley_depth = -1;
  REQUIRE_THROWS_WITH(t.validate(), Catch::Contains("--valley-depth"));
  REQUIRE_THROWS_WITH(parse_variant("sibd+ed"), Catch::Contains("--distance"));
  CostParams c;
  c.alpha = -1;
  REQUIRE_THROWS_WITH(c.validate(), Catch::Contains("--alpha"));
}

TEST_CASE("stipplot tree CLI: bad parameters exit non-zero with the name and leave no output", "[tree][cli]") {
  const test::TempDir tmp;
  const auto dir = tmp.path;
  const std::string in = std::string(STIPPLOT_SOURCE_DIR) + "/examples/horse.png";
  const std::string out = (dir / "t.svg").string(), land = (dir / "t.png").string();
  std::filesystem::remove(out);
  std::filesystem::remove(land);
  struct Case {
    std::string args, name;
  } cases[] = {{"--alpha-bd -1", "--alpha-bd"}, {"--alpha-sibd nan", "--alpha-sibd"}, {"--h -5", "--h"},
               {"--sigma -1", "--sigma"},       {"--distance foo", "--distance"},   {"--valley-depth -2", "--valley-depth"},
               {"--terrain " + (dir / "t.jpg").string(), "--terrain"},
               {"--law sqrt", "--law"},         {"-a 0", "-a"},
               {"-a wide", "-a"},               {"--weight 0.5", "--weight"},
               {"--weight heavy", "--weight"},  {"--weight 2 --separate", "--separate"},
               {"--weight 3 --retrace 1mm", "--retrace"}};
  for (const auto& c : cases) {
    int status = 0;
    const bool own_terrain = c.name == "--terrain";
    const std::string err2 = run_cli(in + " -o " + out + (own_terrain ? "" : " --terrain " + land) + " " + c.args, &status);
    INFO(c.args << " -> " << err2);
    CHECK(status != 0);
    CHECK(err2.find(c.name) != std::string::npos);
    CHECK(!std::filesystem::exists(out));
    CHECK(!std::filesystem::exists(land));
  }
  int status = 0;
  const std::string err = run_cli(in + " -o " + out + " --terrain " + land + " -d csibd -q", &status);
  INFO(err);
  REQUIRE(status == 0);
  REQUIRE(std::filesystem::exists(out));
  REQUIRE(std::filesystem::exists(land));
}

TEST_CASE("tiny images: one point, no segments, terrain still the image size", "[tree][edge-cases]") {
  for (const char* v : {"sibd", "csibd", "bd+sibd"}) {
    for (int w : {1, 2, 5}) {
      const Image img = image_from(w, 1, [](int x, int) { return 30.0 * x; });
      TreeParams p;
      p.variant = parse_variant(v);
      const TreeResult r = tree_pixels(img, p);
      REQUIRE(r.points.size() >= 1);
      for (const auto& l : r.layers) REQUIRE(test::spans(l.edges, r.points.size()));
      const Image land = terrain(r, TerrainParams{});
      REQUIRE(land.width == w);
      REQUIRE(land.height == 1);
      const Drawing d = place_tree(r, Placement{});
      REQUIRE(d.layers.size() == p.variant.layers.size());
    }
  }
}

TEST_CASE("stipplot tree at the hour: a line two pens wide, a loop a tree, and single lines under the paper's law or --weight 1",
          "[tree][cli]") {
  const test::TempDir tmp;
  const std::string in = std::string(STIPPLOT_SOURCE_DIR) + "/examples/horse.png";
  const std::string out = (tmp.path / "t.svg").string();
  const nlohmann::json heavy = test::run_json("tree " + in + " -o " + out + " --page 120x90mm");
  CHECK(heavy["law"] == "tone");
  CHECK(heavy["weight_pens"] == 2.0);
  CHECK(heavy["strokes"] == "loops");
  CHECK(heavy["a_cells"].get<double>() >= 0.62 * 2 - 1e-9);  // the budget only ever spaces the points out
  CHECK(heavy["plan"]["total"]["pen_lifts"].get<size_t>() < heavy["points"].get<size_t>() / 50);

  const nlohmann::json paper = test::run_json("tree " + in + " -o " + out + " --page 120x90mm --law linear");
  CHECK(paper["weight_pens"] == 1.0);
  CHECK(paper["strokes"] == "trails");
  CHECK(paper["a_cells"].get<double>() >= 2 - 1e-9);
  const nlohmann::json thin = test::run_json("tree " + in + " -o " + out + " --page 120x90mm --weight 1");
  CHECK(thin["weight_pens"] == 1.0);
  CHECK(thin["strokes"] == "trails");
  const nlohmann::json separate = test::run_json("tree " + in + " -o " + out + " --page 120x90mm --separate");
  CHECK(separate["strokes"] == "separate");
}

TEST_CASE("tree drawn two pens wide: one closed loop a tree, the pen's width from every edge", "[tree][drawing]") {
  const Image img = shared_image("horse.png", 160);
  TreeParams p;
  p.variant = parse_variant("ed");
  p.tone_law = true;
  p.a = 1.24;
  Placement pl;
  const TreeResult r = tree_pixels(img, p);
  TreeStrokes strokes;
  strokes.link = true;
  strokes.weight = 2;
  const Drawing d = place_tree(r, pl, strokes);
  REQUIRE(d.layers.size() == 1);
  REQUIRE(r.layers[0].edges.size() > 100);
  // Trees: the components of the tree's edges.
  std::vector<uint32_t> up(r.points.size());
  std::iota(up.begin(), up.end(), 0u);
  auto find = [&](uint32_t v) {
    while (up[v] != v) v = up[v] = up[up[v]];
    return v;
  };
  for (const Edge& e : r.layers[0].edges) up[find(e.a)] = find(e.b);
  std::set<uint32_t> trees;
  for (const Edge& e : r.layers[0].edges) trees.insert(find(e.a));
  CHECK(d.layers[0].lines.size() == trees.size());
  for (const auto& l : d.layers[0].lines) {
    CHECK(l.pts.front().x == l.pts.back().x);
    CHECK(l.pts.front().y == l.pts.back().y);
  }
}
