// Pointillism with complementary colours (seed 004): CIEDE2000, Lab, pens, the
// paper's dot-count formula and complement geometry measured on real runs, PDS, CLI.
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>

#include "eval/color_difference.hpp"
#include "eval/fidelity.hpp"
#include "image/image.hpp"
#include "methods/palette.hpp"
#include "methods/pointillism/pens.hpp"
#include "methods/pointillism/pointillism.hpp"
#include "preview/preview.hpp"
#include "test_util.hpp"
#include "util/error.hpp"

using namespace stipplot;
using namespace stipplot::pointillism;
namespace fs = std::filesystem;

namespace {

const std::string kCoffee = std::string(STIPPLOT_SHARED_DIR) + "/images/coffee.png";

// A small synthetic photo: a red disc on a blue-green gradient, with a grey strip.
Image synthetic(int w = 160, int h = 120) {
  Image im;
  im.width = w;
  im.height = h;
  im.rgb.resize(im.pixels() * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &im.rgb[(static_cast<size_t>(y) * w + x) * 3];
      const double dx = x - w * 0.4, dy = y - h * 0.5;
      if (y > h - 20) {
        p[0] = p[1] = p[2] = static_cast<uint8_t>(40 + x * 200 / w);  // grey ramp
      } else if (dx * dx + dy * dy < 30 * 30) {
        p[0] = 200, p[1] = 40, p[2] = 30;
      } else {
        p[0] = 30, p[1] = static_cast<uint8_t>(80 + y), p[2] = static_cast<uint8_t>(120 + x / 2);
      }
    }
  return im;
}

Image coffee_small() {
  Image in = load_image(kCoffee);
  Image out;
  out.width = 300;
  out.height = 200;
  out.rgb.resize(out.pixels() * 3);
  cv::Mat s(in.height, in.width, CV_8UC3, in.rgb.data()), d(out.height, out.width, CV_8UC3, out.rgb.data());
  cv::resize(s, d, d.size(), 0, 0, cv::INTER_AREA);
  return out;
}

}  // namespace

TEST_CASE("scalar sRGB to Lab agrees with OpenCV and round-trips", "[pointillism][lab]") {
  double worst = 0;
  int mismatches = 0;
  for (int r = 0; r < 256; r += 15)
    for (int g = 0; g < 256; g += 15)
      for (int b = 0; b < 256; b += 15) {
        const Color c{static_cast<uint8_t>(r), static_cast<uint8_t>(g), static_cast<uint8_t>(b)};
        const lab::Lab mine = lab::from_srgb(c);
        cv::Mat px(1, 1, CV_32FC3, cv::Scalar(r / 255.0, g / 255.0, b / 255.0)), out;
        cv::cvtColor(px, out, cv::COLOR_RGB2Lab);
        const cv::Vec3f o = out.at<cv::Vec3f>(0, 0);
        worst = std::max(worst, lab::delta_e00(mine, {o[0], o[1], o[2]}));
        if (!(lab::to_srgb(mine) == c)) ++mismatches;
      }
  // OpenCV's float path interpolates the sRGB curve with splines; a third of a JND apart.
  CHECK(worst < 0.5);
  CHECK(mismatches == 0);
}

TEST_CASE("max_chroma is the edge of the sRGB gamut along a hue", "[pointillism][lab]") {
  for (double L : {20.0, 50.0, 80.0})
    for (double h = 0; h < 2 * M_PI; h += 0.7) {
      const double c = lab::max_chroma(L, h);
      CHECK(c > 5);
      CHECK(lab::in_gamut({L, c * std::cos(h), c * std::sin(h)}));
      CHECK_FALSE(lab::in_gamut({L, (c + 0.5) * std::cos(h), (c + 0.5) * std::sin(h)}));
    }
  // Out-of-gamut colours keep their lightness when mapped.
  const Color c = lab::to_srgb({60, 120, -120});
  CHECK(lab::from_srgb(c).L == Approx(60).margin(1.0));
}

TEST_CASE("equal-disc PDS - same sample as brute force - spacing kept - maximal", "[pointillism][pds]") {
  const int w = 90, h = 70;
  for (double d : {1.0, 3.0, 4.5, 6.0}) {
    Rng rng(11);
    const auto order = random_order(static_cast<size_t>(w) * h, rng);
    const auto fast = equal_disc_pds(w, h, d, order);
    CHECK(fast == equal_disc_pds_naive(w, h, d, order));
    // No two closer than d (the paper's rule rejects d_ij < alpha (r_i + r_j)).
    double closest2 = 1e18;
    for (size_t i = 0; i < fast.size(); ++i)
      for (size_t j = i + 1; j < fast.size(); ++j) {
        const double dx = double(fast[i] % w) - double(fast[j] % w), dy = double(fast[i] / w) - double(fast[j] / w);
        closest2 = std::min(closest2, dx * dx + dy * dy);
      }
    CHECK(closest2 >= d * d - 1e-9);
    // Maximal: every pixel is within d of a dot.
    std::vector<uint8_t> covered(static_cast<size_t>(w) * h, 0);
    for (uint32_t p : fast)
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const double dx = x - double(p % w), dy = y - double(p / w);
          if (dx * dx + dy * dy < d * d) covered[static_cast<size_t>(y) * w + x] = 1;
        }
    CHECK(std::count(covered.begin(), covered.end(), 0) == 0);
  }
  // Giving up after misses leaves a sub-sample of the maximal one's size.
  Rng rng(3);
  const auto order = random_order(static_cast<size_t>(w) * h, rng);
  CHECK(equal_disc_pds(w, h, 3, order, 10).size() < equal_disc_pds(w, h, 3, order).size());
}

TEST_CASE("random_order is a permutation - fixed by the seed", "[pointillism][pds]") {
  for (size_t n : {size_t{1}, size_t{1000}, size_t{50000}}) {
    Rng a(5), b(5), c(6);
    const auto x = random_order(n, a);
    std::vector<uint32_t> s = x;
    std::sort(s.begin(), s.end());
    bool identity = true;
    for (size_t i = 0; i < n; ++i) identity = identity && s[i] == i;
    CHECK(identity);
    CHECK(x == random_order(n, b));
    if (n > 1) CHECK(x != random_order(n, c));
  }
  // Unbiased position: the mean position of element 0 over many shuffles is ~ (n-1)/2.
  const size_t n = 10000;
  double sum = 0;
  for (int t = 0; t < 200; ++t) {
    Rng r(100 + t);
    const auto o = random_order(n, r);
    sum += static_cast<double>(std::find(o.begin(), o.end(), 0u) - o.begin());
  }
  CHECK(sum / 200 == Approx((n - 1) / 2.0).epsilon(0.1));
}

TEST_CASE("pure colour and complement lie on the circle - opposite across the a*b* origin", "[pointillism][paper]") {
  const Image img = coffee_small();
  Params p;
  const Result r = paint(img, p);
  int chromatic = 0;
  for (const auto& g : r.regions) {
    if (g.pixels == 0 || g.grey) continue;
    ++chromatic;
    const double ck = std::hypot(g.mean.a, g.mean.b);
    CHECK(std::hypot(g.pure.a, g.pure.b) == Approx(g.circle).margin(1e-9));
    CHECK(std::hypot(g.complement.a, g.complement.b) == Approx(g.circle).margin(1e-9));
    // Opposite sides of the origin, on the line through the origin and p_k.
    CHECK(g.pure.a + g.complement.a == Approx(0).margin(1e-9));
    CHECK(g.pure.b + g.complement.b == Approx(0).margin(1e-9));
    CHECK(g.pure.a * g.mean.a + g.pure.b * g.mean.b == Approx(g.circle * ck).epsilon(1e-9));  // p_i on p_k's side
    CHECK(g.pure.a * g.mean.b - g.pure.b * g.mean.a == Approx(0).margin(1e-6));               // collinear
    // The default circle is gamut-safe at the region's L*.
    CHECK(lab::in_gamut({g.L, g.pure.a, g.pure.b}, 1e-3));
    CHECK(lab::in_gamut({g.L, g.complement.a, g.complement.b}, 1e-3));
  }
  CHECK(chromatic >= 8);
  // The drawn dots carry those hues: a pure dot's hue is p_i's, a complement's is p_j's.
  int checked = 0;
  for (const auto& d : r.strokes) {
    const Region& g = r.regions[d.region];
    if (g.grey) continue;
    const lab::Lab c = lab::from_srgb(d.color);
    if (std::hypot(c.a, c.b) < 8) continue;  // hue of a near-grey 8-bit colour is noise
    const lab::Lab& want = d.complement ? g.complement : g.pure;
    const double dh = std::remainder(std::atan2(c.b, c.a) - std::atan2(want.b, want.a), 2 * M_PI);
    CHECK(std::abs(dh) < 0.15);
    ++checked;
  }
  CHECK(checked > 500);
}

TEST_CASE("N_pi to N_pj ratio per region follows the paper's formula (1)-(2)", "[pointillism][paper]") {
  const Image img = coffee_small();
  for (double W : {0.5, 1.0, 1.4}) {
    Params p;
    p.weight = W;
    p.ebauche = false;
    const Result r = paint(img, p);
    std::map<int, std::pair<size_t, size_t>> counted;  // region -> (pure, complement), from the dots
    for (const auto& d : r.strokes) (d.complement ? counted[d.region].second : counted[d.region].first)++;
    size_t total = 0;
    for (size_t k = 0; k < r.regions.size(); ++k) {
      const Region& g = r.regions[k];
      const auto [np, nc] = counted[static_cast<int>(k)];
      CHECK(np + nc == g.n);
      total += g.n;
      if (g.grey) {
        CHECK(nc == 0);
        continue;
      }
      // Formula from the paper, computed here independently of the method's helper.
      const double dki = std::hypot(g.mean.a - g.pure.a, g.mean.b - g.pure.b);
      const double dkj = std::hypot(g.mean.a - g.complement.a, g.mean.b - g.complement.b);
      const double want = std::min(W * static_cast<double>(g.n) * dkj / (dki + dkj), static_cast<double>(g.n));
      CHECK(std::abs(static_cast<double>(np) - want) <= 0.5 + 1e-9);
      CHECK(nc == g.n - np);
      // With W = 1 and p_k inside the circle, the dots' mean a*b* is p_k itself: the
      // optical mixture keeps the region's colour (|p_k| = R (N_pi - N_pj) / N).
      const double ck = std::hypot(g.mean.a, g.mean.b);
      if (W == 1.0 && g.n >= 20 && ck <= g.circle)
        CHECK(g.circle * (double(np) - double(nc)) / double(g.n) == Approx(ck).margin(g.circle / double(g.n) + 1e-9));
    }
    CHECK(total == r.strokes.size());
  }
  // Helper edge cases: p_k inside and outside the circle, W > 1 clamped.
  lab::Lab pi, pj;
  complementary_pair(3, 4, 10, pi, pj);  // |p_k| = 5, R = 10: Dist = 5 and 15
  CHECK(pure_count(100, {50, 3, 4}, pi, pj, 1.0) == 75);
  CHECK(pure_count(100, {50, 3, 4}, pi, pj, 2.0) == 100);
  complementary_pair(30, 40, 10, pi, pj);  // |p_k| = 50 outside: Dist = 40 and 60
  CHECK(pure_count(100, {50, 30, 40}, pi, pj, 1.0) == 60);
  CHECK(pure_count(100, {50, 30, 40}, pi, pj, 0.5) == 30);
}

TEST_CASE("near-grey regions get no complement - greyscale input stays grey", "[pointillism]") {
  Image grey = Image::from_grey(120, 90, std::vector<uint8_t>(120 * 90, 0));
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 120; ++x) {
      const uint8_t v = static_cast<uint8_t>(x * 2);
      for (int c = 0; c < 3; ++c) grey.rgb[(static_cast<size_t>(y) * 120 + x) * 3 + c] = v;
    }
  const Result r = paint(grey, Params{});
  for (const auto& g : r.regions) CHECK((g.pixels == 0 || g.grey));
  for (const auto& d : r.strokes) {
    CHECK_FALSE(d.complement);
    CHECK(std::abs(int(d.color.r) - int(d.color.g)) <= 2);
    CHECK(std::abs(int(d.color.b) - int(d.color.g)) <= 2);
  }
}

TEST_CASE("ebauche circles take the input colour at their centres - deterministic", "[pointillism]") {
  const Image img = synthetic();
  Params p;
  const Result a = paint(img, p), b = paint(img, p);
  REQUIRE(!a.ebauche.empty());
  for (const auto& d : a.ebauche) {
    const int x = static_cast<int>(d.x), y = static_cast<int>(d.y);
    const uint8_t* px = &img.rgb[(static_cast<size_t>(y) * img.width + x) * 3];
    REQUIRE(d.color == Color{px[0], px[1], px[2]});
  }
  REQUIRE(a.ebauche.size() == b.ebauche.size());
  REQUIRE(a.strokes.size() == b.strokes.size());
  for (size_t i = 0; i < a.strokes.size(); ++i) REQUIRE((a.strokes[i].x == b.strokes[i].x && a.strokes[i].color == b.strokes[i].color));
  // The strokes do not depend on whether the ebauche is drawn.
  p.ebauche = false;
  const Result c = paint(img, p);
  REQUIRE(c.strokes.size() == a.strokes.size());
  for (size_t i = 0; i < a.strokes.size(); ++i) REQUIRE(c.strokes[i].x == a.strokes[i].x);
  // The red disc region: its pure colour is red, its complement blue-green (Fig. 4).
  const Region* red = nullptr;
  for (const auto& d : a.strokes) {
    const int x = static_cast<int>(d.x), y = static_cast<int>(d.y);
    if (std::hypot(x - 64.0, y - 60.0) < 10) {
      red = &a.regions[d.region];
      break;
    }
  }
  REQUIRE(red);
  REQUIRE_FALSE(red->grey);
  CHECK(red->pure.a > 0);
  CHECK(red->complement.a < 0);
}

TEST_CASE("drawing layers - exact colours ebauche first - pens nearest in CIEDE2000", "[pointillism]") {
  const Image img = synthetic();
  const Result r = paint(img, Params{});
  Placement pl;
  const Drawing exact = place(r, pl);
  REQUIRE(exact.layers.size() == 2);
  CHECK(exact.layers[0].pen.name == "ebauche");
  CHECK(exact.layers[0].circles.size() == r.ebauche.size());
  CHECK(exact.layers[1].circles.size() == r.strokes.size());
  for (size_t i = 0; i < r.strokes.size(); ++i) {
    REQUIRE(exact.layers[1].circles[i].filled);
    REQUIRE(exact.layers[1].circles[i].fill == r.strokes[i].color);
  }
  const auto pens = default_pens();
  const Drawing plot = place(r, pl, pens);
  size_t circles = 0, ebauche = 0;
  std::set<std::string> names;
  for (size_t i = 0; i < plot.layers.size(); ++i) {
    const Layer& l = plot.layers[i];
    // Each pen once, named as the palette names it, light pens before dark.
    CHECK(names.insert(l.pen.name).second);
    CHECK(std::any_of(pens.begin(), pens.end(), [&](const Pen& p) { return p.name == l.pen.name && p.color == l.pen.color; }));
    if (i > 0) CHECK(relative_luminance(plot.layers[i - 1].pen.color) >= relative_luminance(l.pen.color));
    // Within a pen, every ebauche circle (pass 0) before any stroke dot (pass 1).
    bool seen_strokes = false;
    for (const auto& c : l.circles) {
      CHECK(c.fill == l.pen.color);
      REQUIRE((c.pass == 0 || c.pass == 1));
      if (c.pass == 1) seen_strokes = true;
      CHECK_FALSE((c.pass == 0 && seen_strokes));
      ebauche += c.pass == 0;
    }
    circles += l.circles.size();
  }
  CHECK(ebauche <= r.ebauche.size());
  CHECK(ebauche > r.ebauche.size() * 9 / 10);
  CHECK(circles <= r.ebauche.size() + r.strokes.size());
  CHECK(circles > (r.ebauche.size() + r.strokes.size()) * 9 / 10);  // the synthetic image has no white
  // White stays paper: an all-white photo needs no pen at all.
  const Image white = Image::from_grey(50, 40, std::vector<uint8_t>(50 * 40, 255));
  CHECK(place(paint(white, Params{}), pl, pens).layers.empty());
  // Nearest pen, checked by brute force for the stroke dots.
  PenMatcher m(pens);
  for (size_t i = 0; i < r.strokes.size(); i += 7) {
    const lab::Lab x = lab::from_srgb(r.strokes[i].color);
    double best = 1e9;
    for (const auto& pen : pens) best = std::min(best, lab::delta_e00(x, lab::from_srgb(pen.color)));
    CHECK(lab::delta_e00(x, lab::from_srgb(pens[m.nearest(r.strokes[i].color)].color)) == Approx(best));
  }
}

TEST_CASE("pen palettes - TOML parsed - malformed files rejected with the line", "[pointillism][pens]") {
  const auto pens = parse_palette(
      "[[pen]]\nname = \"red\"\ncolor = \"#e42a26\"\nwidth = 0.5\n\n[[pen]]\nname = \"blue\"\ncolor = \"#2a62c9\"\n",
      "p.toml", kDefaultPenWidthMm).pens;
  REQUIRE(pens.size() == 2);
  CHECK(pens[0].name == "red");
  CHECK(pens[0].color == Color{0xe4, 0x2a, 0x26});
  CHECK(pens[0].width_mm == 0.5);
  CHECK(pens[1].width_mm == 0.4);
  CHECK_THROWS_AS(parse_palette("", "p.toml"), UserError);
  CHECK_THROWS_AS(parse_palette("[[pen]]\nname = \"x\"\ncolor = \"#zzzzzz\"\n", "p.toml"), UserError);
  CHECK_THROWS_AS(parse_palette("[[pen]]\nname = \"x\"\ncolor = \"#000000\"\nwidth = -1\n", "p.toml"), UserError);
  CHECK_THROWS_AS(parse_palette("[[pen]]\nname = \"x\"\ncolour = \"#000000\"\n", "p.toml"), UserError);
  CHECK_THROWS_AS(parse_palette("[[pen]]\ncolor = \"#000000\"\n", "p.toml"), UserError);
  CHECK_THROWS_WITH(parse_palette("[[pen]\nname = 1", "p.toml"), Catch::Contains("p.toml: line 1"));
  CHECK_THROWS_AS(PenMatcher({}), UserError);
  CHECK(default_pens().size() >= 12);
  // The shipped example file is the built-in palette.
  const auto file =
      load_palette(std::string(STIPPLOT_SOURCE_DIR) + "/src/methods/pointillism/fineliners.toml", kDefaultPenWidthMm).pens;
  const auto builtin = default_pens();
  REQUIRE(file.size() == builtin.size());
  for (size_t i = 0; i < file.size(); ++i) {
    CHECK(file[i].name == builtin[i].name);
    CHECK(file[i].color == builtin[i].color);
    CHECK(file[i].width_mm == builtin[i].width_mm);
  }
  CHECK(builtin[0].name == "black");
  CHECK(builtin[0].color == Color{0x1e, 0x1e, 0x1e});
  CHECK(builtin[0].width_mm == 0.4);
}

TEST_CASE("pointillism: bad parameters are rejected naming the option", "[pointillism]") {
  const Image img = synthetic(40, 30);
  auto bad = [&](auto set, const char* name) {
    Params p;
    set(p);
    CHECK_THROWS_WITH(paint(img, p), Catch::Contains(name));
  };
  bad([](Params& p) { p.regions = 0; }, "--regions");
  bad([](Params& p) { p.weight = -0.1; }, "--weight");
  bad([](Params& p) { p.weight = std::nan(""); }, "--weight");
  bad([](Params& p) { p.radius_px = 0; }, "--radius");
  bad([](Params& p) { p.radius_px = -3; }, "--radius");
  bad([](Params& p) { p.radius_px = std::nan(""); }, "--radius");
  bad([](Params& p) { p.alpha_ebauche = 0; }, "--alpha-ebauche");
  bad([](Params& p) { p.alpha_ebauche = 0.1; }, "--alpha-ebauche");  // circles closer than a pixel
  bad([](Params& p) { p.chroma = -1; }, "--chroma");
  bad([](Params& p) { p.blur_sigma = std::numeric_limits<double>::infinity(); }, "--blur");
}

TEST_CASE("the ebauche brings the blurred drawing closer to the input (mean CIEDE2000)", "[pointillism][fidelity]") {
  const Image img = coffee_small();
  Placement pl;
  pl.page = {150, 100};
  pl.margin_mm = 0;
  auto measure = [&](bool ebauche) {
    Params p;
    p.ebauche = ebauche;
    const Drawing d = pointillism::pointillism(img, p, pl);
    PreviewOptions po;
    po.ink_multiplies = false;
    po.dpi = 25.4 / pl.transform(img.width, img.height).mm_per_px();
    const Image page = render_preview(d, po);
    const Image drawn = crop_to_image(page, pl.transform(img.width, img.height), img.width, img.height);
    return mean_delta_e00_blurred(img, drawn, 2 * p.radius_px);
  };
  const double with = measure(true), without = measure(false);
  CHECK(with < without);
  CHECK(with < 12);
  CHECK(mean_delta_e00_blurred(img, img, 6) == Approx(0).margin(1e-9));
}

TEST_CASE("CLI - pointillism writes SVG - preview and JSON - bad input fails with no file", "[pointillism][cli]") {
  test::TempDir t;
  test::RunResult ok = test::run_cli("pointillism " + kCoffee + " -o " + t.file("a.svg") + " --preview " + t.file("a.png") +
               " --regions 6 --weight 1.2 --json --fidelity");
  INFO(ok.err);
  REQUIRE(ok.exit_code == 0);
  CHECK(fs::exists(t.file("a.svg")));
  CHECK(fs::exists(t.file("a.png")));
  CHECK(ok.out.find("\"mean_de00\"") != std::string::npos);
  CHECK(ok.out.find("\"command\":\"pointillism\"") != std::string::npos);
  const std::string svg = test::read_file(t.file("a.svg"));
  CHECK(svg.find("ebauche") < svg.find("divided strokes"));

  test::RunResult pens = test::run_cli("pointillism " + kCoffee + " -o " + t.file("p.svg") + " --plot-pens --radius 1mm --json");
  REQUIRE(pens.exit_code == 0);
  // One layer a pen, each named as the pen (its ebauche and dots together).
  const auto pj = nlohmann::json::parse(pens.out);
  REQUIRE(pj["layers"].size() >= 2);
  std::set<std::string> pen_names;
  for (const auto& l : pj["layers"]) {
    CHECK(pen_names.insert(l["pen"].get<std::string>()).second);
    CHECK(test::read_file(t.file("p.svg")).find(l["pen"].get<std::string>()) != std::string::npos);
  }

  for (const std::string& args :
       {std::string("--regions 0"), std::string("--weight -1"), std::string("--radius 0"), std::string("--radius -2"),
        std::string("--weight nan"), std::string("--alpha-ebauche 0"), std::string("--pens ") + t.file("empty.toml")}) {
    std::ofstream(t.file("empty.toml")) << "# no pens\n";
    test::RunResult r = test::run_cli("pointillism " + kCoffee + " -o " + t.file("bad.svg") + " " + args);
    INFO(args << ": " << r.err);
    CHECK(r.exit_code != 0);
    CHECK(r.err.find("error") != std::string::npos);
    CHECK_FALSE(fs::exists(t.file("bad.svg")));
  }
  test::RunResult help = test::run_cli("pointillism --help");
  CHECK(help.out.find("Example:") != std::string::npos);
}

TEST_CASE("with pens the ebauche is hatched per colour region: fewer pen lifts, more ink, truer colour in the same time", "[pointillism][cli]") {
  test::TempDir t;
  auto run = [&](const std::string& style) {
    test::RunResult r = test::run_cli("pointillism " + kCoffee + " --plot-pens --page 148x105mm --time 10min --ebauche " + style +
                                      " -o " + t.file(style + ".svg") + " --fidelity --json");
    INFO(style << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    return nlohmann::json::parse(r.out);
  };
  const auto hatch = run("hatch"), circles = run("circles");
  CHECK(hatch["ebauche_style"] == "hatch");
  CHECK(circles["ebauche_style"] == "circles");
  size_t lines = 0;
  for (const auto& l : hatch["layers"]) lines += l["lines"].get<size_t>();
  CHECK(lines > 0);  // the ebauche's hatching
  for (const auto& j : {hatch, circles}) CHECK(j["plan"]["total"]["seconds"].get<double>() <= 600);
  const auto& h = hatch["plan"]["total"];
  const auto& c = circles["plan"]["total"];
  INFO("hatch: " << h.dump() << " de " << hatch["mean_de00"] << "; circles: " << c.dump() << " de " << circles["mean_de00"]);
  CHECK(h["pen_lifts"].get<double>() < 0.8 * c["pen_lifts"].get<double>());
  CHECK(h["pen_down_mm"].get<double>() > 1.5 * c["pen_down_mm"].get<double>());
  CHECK(hatch["mean_de00"].get<double>() < circles["mean_de00"].get<double>() - 5);
  // Exact colours (no pens) keep the paper's circles.
  test::RunResult exact = test::run_cli("pointillism " + kCoffee + " --page 148x105mm -o " + t.file("e.svg") + " --json");
  REQUIRE(exact.exit_code == 0);
  CHECK(nlohmann::json::parse(exact.out)["ebauche_style"] == "circles");
  test::RunResult bad = test::run_cli("pointillism " + kCoffee + " --plot-pens --ebauche scribble -o " + t.file("b.svg"));
  CHECK(bad.exit_code != 0);
  CHECK(bad.err.find("--ebauche") != std::string::npos);
  CHECK_FALSE(fs::exists(t.file("b.svg")));
}
