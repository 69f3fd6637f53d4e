// Colour sketches: pen probabilities, stroke directions, lightening, palettes, the
// colour-fidelity claim and the CLI.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "eval/fidelity.hpp"
#include "image/image.hpp"
#include "methods/palette.hpp"
#include "eval/color_difference.hpp"
#include "methods/sketch/sketch.hpp"
#include "test_util.hpp"
#include "util/error.hpp"

using namespace stipplot;
using namespace stipplot::sketch;

namespace {

// Patches of the given colours, `size` px square, in a row, plus a white patch at the end.
Image patches(const std::vector<Color>& colours, int size) {
  Image im;
  im.width = size * static_cast<int>(colours.size() + 1);
  im.height = size;
  im.rgb.assign(im.pixels() * 3, 255);
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const size_t k = static_cast<size_t>(x / size);
      if (k >= colours.size()) continue;
      uint8_t* p = &im.rgb[(static_cast<size_t>(y) * im.width + x) * 3];
      p[0] = colours[k].r;
      p[1] = colours[k].g;
      p[2] = colours[k].b;
    }
  return im;
}

Placement one_px_cells() {
  Placement pl;
  pl.page = {100, 100};
  pl.margin_mm = 5;
  return pl;
}

Vec2 centre(const Stroke& s) {
  Vec2 c;
  for (auto p : s.line.pts) {
    c.x += p.x;
    c.y += p.y;
  }
  c.x /= s.line.pts.size();
  c.y /= s.line.pts.size();
  return c;
}

// For every pen, the patch (by index) that received most of its strokes.
std::map<std::string, int> busiest_patch(const Image& im, const SketchParams& p, const Placement& pl, int size) {
  SketchResult r = sketch_strokes(im, p, pl);
  const PageTransform T = pl.transform(im.width, im.height);
  std::map<std::string, int> out;
  for (const auto& ps : r.pens) {
    std::vector<int> counts(im.width / size, 0);
    for (const auto& s : ps.strokes) {
      Vec2 px = T.unmap(centre(s));
      int k = std::clamp(static_cast<int>(px.x) / size, 0, static_cast<int>(counts.size()) - 1);
      counts[k]++;
    }
    out[ps.pen.name] = static_cast<int>(std::max_element(counts.begin(), counts.end()) - counts.begin());
  }
  return out;
}

Image ramp(int w, int h, double fx, double fy) {
  Image im;
  im.width = w;
  im.height = h;
  im.rgb.resize(im.pixels() * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto v = static_cast<uint8_t>(std::lround(std::clamp(40 + fx * x + fy * y, 0.0, 255.0)));
      for (int c = 0; c < 3; ++c) im.rgb[(static_cast<size_t>(y) * w + x) * 3 + c] = v;
    }
  return im;
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

}  // namespace

TEST_CASE("pixels of a pen's exact colour get the most of that pen's points", "[sketch]") {
  const int size = 24;
  SketchParams p;
  p.cell = Length{1, true};
  SECTION("rgb: the paper's 8 pens") {
    auto pens = builtin_pens(ColorSpace::Rgb, 0.3);
    std::vector<Color> cols;
    for (const auto& pen : pens) cols.push_back(pen.color);
    auto best = busiest_patch(patches(cols, size), p, one_px_cells(), size);
    for (size_t k = 0; k < pens.size(); ++k) CHECK(best[pens[k].name] == static_cast<int>(k));
  }
  SECTION("hsi: the six hue pens") {
    p.space = ColorSpace::Hsi;
    auto pens = builtin_pens(ColorSpace::Hsi, 0.3);
    std::vector<Color> cols;
    for (const auto& pen : pens) cols.push_back(pen.color);
    auto best = busiest_patch(patches(cols, size), p, one_px_cells(), size);
    for (size_t k = 0; k < pens.size(); ++k)
      if (pens[k].name != "black") CHECK(best[pens[k].name] == static_cast<int>(k));  // black ties on every grey
  }
  SECTION("a user palette of non-primary pens") {
    p.space = ColorSpace::Pens;
    p.pens = parse_palette(R"(
      [[pen]]
      name = "sienna"
      color = "#a0522d"
      [[pen]]
      name = "navy"
      color = "#1f2a6b"
      [[pen]]
      name = "olive"
      color = "#7a7a1e"
      [[pen]]
      name = "pink"
      color = "#f4a3b8"
      [[pen]]
      name = "teal"
      color = "#1d8a8a"
    )").pens;
    std::vector<Color> cols;
    for (const auto& pen : p.pens) cols.push_back(pen.color);
    auto best = busiest_patch(patches(cols, size), p, one_px_cells(), size);
    for (size_t k = 0; k < p.pens.size(); ++k) CHECK(best[p.pens[k].name] == static_cast<int>(k));
  }
}

TEST_CASE("rgb probabilities are the paper's: p = max(0, (d - D)/d)", "[sketch]") {
  SketchParams p;
  auto pens = builtin_pens(ColorSpace::Rgb, 0.3);
  Image px = patches({Color{255, 0, 0}, Color{128, 128, 128}, Color{200, 60, 40}}, 1);
  auto prob = pen_probabilities(px, p, pens);
  // pens: red 0, ..., black 6, grey 7; cells: red, grey, (200,60,40), white
  CHECK(prob[0][0] == Approx(1.0));
  CHECK(prob[7][1] == Approx(1.0).margin(0.02));  // 128/255 vs 0.5
  const double D = std::sqrt(std::pow(1 - 200 / 255.0, 2) + std::pow(60 / 255.0, 2) + std::pow(40 / 255.0, 2));
  CHECK(prob[0][2] == Approx((std::sqrt(3.0) / 2 - D) / (std::sqrt(3.0) / 2)).epsilon(1e-5));
  CHECK(prob[7][2] == 0);   // grey's reach is only 0.15
  CHECK(prob[6][3] == 0);   // black never on white
  SECTION("hsi: hue difference and exp(-5 s) for black") {
    p.space = ColorSpace::Hsi;
    auto hp = pen_probabilities(patches({Color{255, 128, 0}}, 1), p, builtin_pens(ColorSpace::Hsi, 0.3));
    // orange (hue pi/6 - ish): between red (0) and yellow (pi/3)
    CHECK(hp[0][0] > 0.3);
    CHECK(hp[1][0] > 0.3);
    CHECK(hp[0][0] + hp[1][0] == Approx(1.0).margin(0.02));
    CHECK(hp[2][0] == 0);
    CHECK(hp[6][0] == Approx(std::exp(-5.0)).epsilon(1e-4));  // saturation 1
    CHECK(hp[6][1] == Approx(1.0));                           // white: saturation 0
    CHECK(hp[0][1] == 0);                                     // no hue on white
  }
}

TEST_CASE("hsi black: the paper's saturation misses dark tinted pixels, chroma does not", "[sketch]") {
  SketchParams p;
  p.space = ColorSpace::Hsi;
  const auto pens = builtin_pens(ColorSpace::Hsi, 0.3);  // green 2, black 6
  const Image dark = patches({Color{10, 25, 12}}, 1);     // a near-black sky with a green tint
  auto paper = pen_probabilities(dark, p, pens);
  CHECK(paper[6][0] < 0.2f);   // HSI saturation 0.36: black loses...
  CHECK(paper[2][0] > 0.8f);   // ...to a strong green (hue 8 degrees off the pen's)
  p.hsi_black = HsiBlack::Chroma;
  auto chroma = pen_probabilities(dark, p, pens);
  CHECK(chroma[6][0] == Approx(std::exp(-5.0 * 15 / 255)).epsilon(1e-5));
  CHECK(chroma[2][0] == Approx((1 - chroma[6][0]) * paper[2][0]).epsilon(1e-5));
  CHECK(chroma[6][0] > chroma[2][0]);
  CHECK_THROWS_AS(parse_hsi_black("lab"), UserError);
}

TEST_CASE("strokes run across the gradient, longer and thicker where it is strong", "[sketch]") {
  SketchParams p;
  p.cell = Length{1, true};
  p.edge_low = 0.001;
  p.edge_high = 0.004;
  p.max_passes = 3;
  auto check_dir = [&](const Image& im, double ex, double ey) {
    const Placement pl = one_px_cells();
    const PageTransform T = pl.transform(im.width, im.height);
    SketchResult r = sketch_strokes(im, p, pl);
    size_t n = 0, aligned = 0, full = 0;
    for (const auto& ps : r.pens)
      for (const auto& s : ps.strokes) {
        // the border cells see a one-sided (weaker) gradient: judge the interior
        const Vec2 c = T.unmap(centre(s));
        if (c.x < 3 || c.y < 3 || c.x > im.width - 3 || c.y > im.height - 3) continue;
        const Vec2 a = s.line.pts[0], b = s.line.pts[1];
        const double dx = b.x - a.x, dy = b.y - a.y, len = std::hypot(dx, dy);
        CHECK(len == Approx(p.edge_mm).epsilon(1e-6));
        aligned += std::abs(dx * ex + dy * ey) / len > 0.999;
        full += s.line.pts.size() == 2 * static_cast<size_t>(p.max_passes);
        ++n;
      }
    REQUIRE(n > 100);
    CHECK(aligned == n);
    CHECK(full == n);
  };
  SECTION("horizontal ramp: vertical strokes") { check_dir(ramp(120, 60, 1.2, 0), 0, 1); }
  SECTION("vertical ramp: horizontal strokes") { check_dir(ramp(60, 120, 0, 1.2), 1, 0); }
  SECTION("diagonal ramp: strokes along the anti-diagonal") {
    check_dir(ramp(100, 100, 0.8, 0.8), 1 / std::sqrt(2.0), -1 / std::sqrt(2.0));
  }
  SECTION("flat image: short single hatch marks") {
    p.hatch_deg = 0;
    SketchResult r = sketch_strokes(ramp(80, 80, 0, 0), p, one_px_cells());
    size_t n = 0;
    for (const auto& ps : r.pens)
      for (const auto& s : ps.strokes) {
        REQUIRE(s.line.pts.size() == 2);
        CHECK(s.line.pts[1].x - s.line.pts[0].x == Approx(p.mark_mm).epsilon(1e-6));
        CHECK(s.line.pts[1].y == Approx(s.line.pts[0].y));
        ++n;
      }
    CHECK(n > 100);
  }
}

TEST_CASE("lightening: paper preview lightens, the plot thins in proportion", "[sketch]") {
  SketchParams p;
  p.space = ColorSpace::Hsi;
  p.cell = Length{1, true};
  const Image grey = ramp(100, 100, 0, 0);  // luma 40/255: black pen, t = 40/255
  const Image light = [&] { Image l = grey; for (auto& v : l.rgb) v = 200; return l; }();
  for (const Image* im : {&grey, &light}) {
    SketchResult r = sketch_strokes(*im, p, one_px_cells());
    REQUIRE(r.pens.back().pen.name == "black");
    const auto& strokes = r.pens.back().strokes;
    REQUIRE(strokes.size() > 1000);
    size_t plotted = 0;
    for (const auto& s : strokes) plotted += s.plotted;
    const double t = im->rgb[0] / 255.0;
    CHECK(strokes[0].lighten == Approx(t).epsilon(1e-5));
    // p = 1 (capped): lambda = 4 marks per cell; keep k so that 1 - exp(-4k) = (1 - t)(1 - exp(-4))
    const double pc = -std::expm1(-4.0), k = std::log1p(-(1 - t) * pc) / std::log1p(-pc);
    CHECK(static_cast<double>(plotted) / strokes.size() == Approx(k).margin(0.02));
    CHECK(k < 1 - t);
    // hue pens get nothing on grey
    for (size_t c = 0; c + 1 < r.pens.size(); ++c) CHECK(r.pens[c].strokes.empty());
  }
  SECTION("rgb mode does not lighten unless asked") {
    p.space = ColorSpace::Rgb;
    SketchResult r = sketch_strokes(light, p, one_px_cells());
    for (const auto& ps : r.pens)
      for (const auto& s : ps.strokes) CHECK(s.plotted);
  }
}

TEST_CASE("the same seed gives the same sketch, another seed another", "[sketch]") {
  SketchParams p;
  Image im = patches({Color{200, 30, 30}, Color{20, 20, 20}}, 40);
  auto a = sketch_strokes(im, p, Placement{}), b = sketch_strokes(im, p, Placement{});
  p.seed = 2;
  auto c = sketch_strokes(im, p, Placement{});
  REQUIRE(a.pens.size() == b.pens.size());
  bool differ = false;
  for (size_t k = 0; k < a.pens.size(); ++k) {
    REQUIRE(a.pens[k].strokes.size() == b.pens[k].strokes.size());
    for (size_t i = 0; i < a.pens[k].strokes.size(); ++i) CHECK(a.pens[k].strokes[i].line.pts == b.pens[k].strokes[i].line.pts);
    for (size_t i = 0; i < std::min(a.pens[k].strokes.size(), c.pens[k].strokes.size()); ++i)
      differ = differ || a.pens[k].strokes[i].line.pts != c.pens[k].strokes[i].line.pts;
  }
  CHECK(differ);
}

TEST_CASE("tiny and uniform images do not hang or divide by zero", "[sketch]") {
  SketchParams p;
  for (ColorSpace s : {ColorSpace::Rgb, ColorSpace::Hsi}) {
    p.space = s;
    Image one = patches({Color{0, 0, 0}}, 1);  // 2x1: black, white
    one.width = 1;
    one.rgb.resize(3);
    CHECK_NOTHROW(sketch_strokes(one, p, Placement{}));
    Image white = ramp(50, 50, 0, 0);
    for (auto& v : white.rgb) v = 255;
    auto r = sketch_strokes(white, p, Placement{});
    if (s == ColorSpace::Rgb) CHECK(r.plotted_strokes() == 0);
    Image black = white;
    for (auto& v : black.rgb) v = 0;
    CHECK(sketch_strokes(black, p, Placement{}).plotted_strokes() > 0);
  }
}

TEST_CASE("sketch: bad parameters are rejected naming the option", "[sketch]") {
  SketchParams p;
  auto bad = [&](auto change, const char* name) {
    SketchParams q = p;
    change(q);
    REQUIRE_THROWS_AS(q.validate(), UserError);
    try {
      q.validate();
    } catch (const UserError& e) {
      CHECK(std::string(e.what()).find(name) != std::string::npos);
    }
  };
  bad([](SketchParams& q) { q.cell.value = -1; }, "--cell");
  bad([](SketchParams& q) { q.mark_mm = std::nan(""); }, "--mark");
  bad([](SketchParams& q) { q.edge_low = 0.5; q.edge_high = 0.2; }, "--edge-high");
  bad([](SketchParams& q) { q.max_passes = 0; }, "--passes");
  bad([](SketchParams& q) { q.reach = -1; }, "--reach");
  bad([](SketchParams& q) { q.space = ColorSpace::Pens; }, "--pens");
  CHECK_THROWS_AS(parse_color_space("cmyk"), UserError);
  // a grid or stroke count beyond reason is refused up front, naming --cell
  SketchParams tiny_cells;
  tiny_cells.cell = Length{0.001, false};
  Image black = patches({Color{0, 0, 0}}, 8);
  CHECK_THROWS_WITH(sketch_strokes(black, tiny_cells, Placement{}), Catch::Contains("--cell"));
  CHECK_THROWS_AS(parse_lighten("maybe"), UserError);
}

TEST_CASE("palettes: good files parse, bad ones are rejected clearly", "[sketch][palette]") {
  Palette ok = parse_palette(R"(
    name = "three fineliners"
    [[pen]]
    name = "red"
    color = "#D7261E"
    width = 0.4
    [[pen]]
    name = "blue"
    color = "#1f4e9c"
    [[pen]]
    name = "black"
    color = "#000"
    width = 1
  )");
  CHECK(ok.name == "three fineliners");
  REQUIRE(ok.pens.size() == 3);
  CHECK(ok.pens[0].color == Color{0xd7, 0x26, 0x1e});
  CHECK(ok.pens[0].width_mm == 0.4);
  CHECK(ok.pens[1].width_mm == 0.3);
  CHECK(ok.pens[2].width_mm == 1.0);
  auto rejects = [](const std::string& text, const std::string& words) {
    INFO(text);
    try {
      parse_palette(text, "p.toml");
      FAIL("accepted a bad palette");
    } catch (const UserError& e) {
      const std::string msg = e.what();
      INFO(msg);
      CHECK(msg.rfind("p.toml: ", 0) == 0);
      CHECK(msg.find(words) != std::string::npos);
      CHECK(msg.find('\n') == std::string::npos);
    }
  };
  rejects("", "no pens");
  rejects("name = \"empty\"", "no pens");
  rejects("pen = []", "no pens");
  rejects("pen = 3", "[[pen]]");
  rejects("[[pen]]\nname = \"red\"\ncolor = \"#ff00zz\"", "bad color '#ff00zz'");
  rejects("[[pen]]\nname = \"red\"\ncolor = \"#12345\"", "bad color");
  rejects("[[pen]]\nname = \"red\"\ncolor = 0xff0000", "'color' must be a string");
  rejects("[[pen]]\nname = \"red\"", "missing 'color'");
  rejects("[[pen]]\ncolor = \"#ff0000\"", "missing 'name'");
  rejects("[[pen]]\nname = \"\"\ncolor = \"#ff0000\"", "non-empty");
  rejects("[[pen]]\nname = \"a\"\ncolor = \"#ff0000\"\n[[pen]]\nname = \"a\"\ncolor = \"#00ff00\"", "duplicate pen name 'a'");
  rejects("[[pen]]\nname = \"a\"\ncolor = \"#ff0000\"\nwidth = -1", "'width'");
  rejects("[[pen]]\nname = \"a\"\ncolor = \"#ff0000\"\nwidht = 0.3", "unknown key 'widht'");
  rejects("[[pen]\nname = \"a\"", "line 1");
  CHECK_THROWS_AS(load_palette("/nonexistent/pens.toml"), UserError);
  // the example palettes in the repository all load
  for (const auto& e : std::filesystem::directory_iterator(std::string(STIPPLOT_SOURCE_DIR) + "/examples/pens")) {
    INFO(e.path());
    CHECK(load_palette(e.path().string()).pens.size() >= 1);
  }
}

TEST_CASE("colour fidelity: the rgb pens beat a one-pen black sketch (mean dE00, blurred)", "[sketch][color]") {
  const Image img = load_image(std::string(STIPPLOT_SOURCE_DIR) + "/examples/coffee.png");
  Placement pl;  // A5: a smaller sketch, same method, keeps the test quick
  pl.page = {148, 210};
  pl.landscape = true;
  auto measure = [&](const SketchParams& p) {
    SketchResult r = sketch_strokes(img, p, pl);
    Image prev = render_sketch_preview(r, 100, PreviewStyle::Paper);
    const PageTransform T = pl.transform(img.width, img.height);
    Image crop = crop_to_image(prev, T, img.width, img.height);
    return mean_delta_e00_blurred(img, crop, 2 * r.cell_mm / T.mm_per_px());
  };
  SketchParams rgb;
  SketchParams hsi;
  hsi.space = ColorSpace::Hsi;
  SketchParams black;
  black.space = ColorSpace::Pens;
  black.pens = {Pen{"black", colors::black, 0.3}};
  const double e_rgb = measure(rgb), e_hsi = measure(hsi), e_black = measure(black);
  WARN("coffee mean dE00 (blurred): rgb " << e_rgb << ", hsi " << e_hsi << ", black only " << e_black);
  CHECK(e_rgb < 0.8 * e_black);
  CHECK(e_rgb > 1);  // a sketch is not the photo
}

TEST_CASE("sketch CLI: both spaces and a palette, one layer per pen, bad input refused", "[sketch][cli]") {
  test::TempDir t;
  const std::string img = std::string(STIPPLOT_SOURCE_DIR) + "/examples/horse.png";
  const std::string pal = std::string(STIPPLOT_SOURCE_DIR) + "/examples/pens/fineliner12.toml";
  for (const std::string& mode : std::vector<std::string>{"--space rgb", "--space hsi", "--pens " + pal}) {
    auto r = test::run_cli("sketch " + img + " " + mode + " -o " + t.file("o.svg") + " --preview " + t.file("p.png") +
                           " --page 120x90mm --preview-dpi 100 --measure --json");
    INFO(mode << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    auto j = nlohmann::json::parse(r.out);
    CHECK(j["linked"]["strokes"].get<size_t>() > 100);                          // marks,
    CHECK(j["primitives"].get<size_t>() < j["linked"]["strokes"].get<size_t>() / 4);  // linked into scribbles
    CHECK(j["delta_e00"].get<double>() > 0);
    CHECK(std::filesystem::file_size(t.file("p.png")) > 1000);
    const std::string svg = test::read_file(t.file("o.svg"));
    for (const auto& l : j["layers"]) CHECK(svg.find(l["pen"].get<std::string>()) != std::string::npos);
  }
  write_text(t.file("dup.toml"), "[[pen]]\nname = \"a\"\ncolor = \"#ff0000\"\n[[pen]]\nname = \"a\"\ncolor = \"#000000\"\n");
  auto bad = test::run_cli("sketch " + img + " --pens " + t.file("dup.toml") + " -o " + t.file("bad.svg"));
  CHECK(bad.exit_code != 0);
  CHECK(bad.err.find("duplicate pen name 'a'") != std::string::npos);
  CHECK(!std::filesystem::exists(t.file("bad.svg")));
  auto hsi_pens = test::run_cli("sketch " + img + " --pens " + pal + " --space hsi -o " + t.file("bad.svg"));
  CHECK(hsi_pens.exit_code != 0);
  CHECK(hsi_pens.err.find("--pens") != std::string::npos);
  auto space = test::run_cli("sketch " + img + " --space lab -o " + t.file("bad.svg"));
  CHECK(space.exit_code != 0);
  CHECK(space.err.find("--space") != std::string::npos);
  auto help = test::run_cli("sketch --help");
  CHECK(help.exit_code == 0);
  CHECK(help.out.find("Example") != std::string::npos);
}

namespace {
// Pen-down length of a drawing's lines with x in [x0, x1) on the page, per pen (each
// segment cut into pieces of at most 0.05 mm, counted where their middle lies).
std::map<std::string, double> ink_between(const Drawing& d, double x0, double x1) {
  std::map<std::string, double> len;
  test::for_each_line_piece(d, [&](const Layer& l, double x, double piece) {
    if (x >= x0 && x < x1) len[l.pen.name] += piece;
  });
  return len;
}
}  // namespace

TEST_CASE("sketch ground, one pen: darker patches take more crossed lines, near-white none", "[sketch][ground]") {
  // Near white, light grey, dark grey, black, then white: 5 patches of 60 px on 100 mm.
  const Image img = patches({Color{240, 240, 240}, Color{200, 200, 200}, Color{110, 110, 110}, Color{0, 0, 0}}, 60);
  Placement pl;
  pl.page = {120, 40};
  pl.margin_mm = 10;  // the image: 100 x 20 mm, 20 mm a patch
  const std::vector<Pen> pens{Pen{"black", colors::black, 0.3}};
  const hatch::PenGrid g = ground_grid(img, pens, pl);
  REQUIRE(g.amount.size() == g.pen.size());
  const Drawing d = ground_drawing(g, pens, pl, 0.5);
  std::vector<double> ink;
  for (int p = 0; p < 5; ++p) ink.push_back(ink_between(d, 10 + 20 * p + 4, 10 + 20 * p + 16)["black"]);
  INFO("ink per patch (mm): " << ink[0] << " " << ink[1] << " " << ink[2] << " " << ink[3] << " " << ink[4]);
  CHECK(ink[0] == 0);  // too light for one direction of lines: the paper's
  CHECK(ink[1] > 0);
  CHECK(ink[2] > 1.7 * ink[1]);  // two directions where light grey takes one
  CHECK(ink[3] > 2.5 * ink[1]);  // three
  CHECK(ink[4] == 0);
  // More coverage, more lines: the budget's knob is monotone.
  double total_lo = 0, total_hi = 0;
  for (const auto& [pen, mm] : ink_between(ground_drawing(g, pens, pl, 0.3), 0, 200)) total_lo += mm;
  for (const auto& [pen, mm] : ink_between(ground_drawing(g, pens, pl, 0.6), 0, 200)) total_hi += mm;
  CHECK(total_hi > 1.8 * total_lo);
}

TEST_CASE("sketch ground, pens: each colour field takes its nearest pen, white the paper", "[sketch][ground]") {
  const Image img = patches({Color{230, 20, 20}, Color{20, 20, 230}}, 60);
  Placement pl;
  pl.page = {80, 40};
  pl.margin_mm = 10;  // 20 mm a patch: red, blue, white
  const std::vector<Pen> pens{Pen{"red", Color{255, 0, 0}, 0.3}, Pen{"blue", Color{0, 0, 255}, 0.3},
                              Pen{"black", colors::black, 0.3}};
  const hatch::PenGrid g = ground_grid(img, pens, pl);
  CHECK(g.amount.empty());
  const Drawing d = ground_drawing(g, pens, pl, 0.5);
  auto red = ink_between(d, 14, 26), blue = ink_between(d, 34, 46), white = ink_between(d, 54, 66);
  CHECK(red["red"] > 100);
  CHECK(red["blue"] == 0);
  CHECK(blue["blue"] > 100);
  CHECK(blue["red"] == 0);
  CHECK(red["black"] + blue["black"] == 0);
  CHECK(white.empty());
}

TEST_CASE("sketch --ground: a short --time lays the tone as hatching, a long one the strokes alone", "[sketch][ground][cli]") {
  test::TempDir t;
  const std::string img = std::string(STIPPLOT_SOURCE_DIR) + "/examples/coffee.png";
  auto run = [&](const std::string& opts) {
    auto r = test::run_cli("sketch " + img + " -o " + t.file("o.svg") + " --page A5 --landscape --measure --json " + opts);
    INFO(opts << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    return nlohmann::json::parse(r.out);
  };
  const auto ground = run("--time 10min"), bare = run("--time 10min --ground none"), slow = run("--time 100h");
  REQUIRE(ground.contains("ground"));
  CHECK(!bare.contains("ground"));
  CHECK(!slow.contains("ground"));  // auto: the strokes alone fit
  for (const auto* j : {&ground, &bare}) CHECK((*j)["plan"]["total"]["seconds"].get<double>() <= 600);
  // Seen from arm's length the ground brings the colour nearer the photo's, and the picture.
  CHECK(ground["delta_e_view"].get<double>() < bare["delta_e_view"].get<double>() - 5);
  CHECK(ground["ssim_view"].get<double>() > bare["ssim_view"].get<double>());
  auto bad = test::run_cli("sketch " + img + " -o " + t.file("bad.svg") + " --ground paint");
  CHECK(bad.exit_code != 0);
  CHECK(bad.err.find("--ground") != std::string::npos);
  CHECK(!std::filesystem::exists(t.file("bad.svg")));
}
