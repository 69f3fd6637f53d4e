// Tone hatching: more ink where the photo is darker, none on white, every line inside
// its band and the page's margins, zig-zags that never leave the region, the budget,
// bad parameters refused in one line, and the same drawing every time.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "methods/hatch/hatch.hpp"
#include "methods/hatch/hatch_lines.hpp"
#include "methods/palette.hpp"
#include "test_util.hpp"
#include "util/error.hpp"
#include "util/threads.hpp"

using namespace stipplot;
using namespace stipplot::hatch;

namespace {

Image grey_image(int w, int h, const std::function<double(int, int)>& grey) {
  std::vector<uint8_t> g(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) g[size_t(y) * w + x] = uint8_t(std::clamp(std::lround(grey(x, y)), 0L, 255L));
  return Image::from_grey(w, h, g);
}

Placement page(double w, double h, double margin) {
  Placement pl;
  pl.page = PageSpec{w, h};
  pl.margin_mm = margin;
  return pl;
}

// Pen-down length of the drawing's lines in each of `n` vertical strips of [x0, x1],
// each segment cut into pieces of at most 0.05 mm, counted where their middle lies.
std::vector<double> length_per_strip(const Drawing& d, double x0, double x1, int n) {
  std::vector<double> len(size_t(n), 0);
  test::for_each_line_piece(d, [&](const Layer&, double x, double piece) {
    len[size_t(std::clamp(int((x - x0) / (x1 - x0) * n), 0, n - 1))] += piece;
  });
  return len;
}

size_t line_count(const Drawing& d) {
  size_t n = 0;
  for (const Layer& l : d.layers) n += l.lines.size();
  return n;
}

}  // namespace

TEST_CASE("hatch: darker regions get more ink per area, near the tone the photo asks for", "[hatch]") {
  // Black on the left to white on the right, on a 200 x 100 mm drawing.
  const Image img = grey_image(400, 200, [](int x, int) { return 255.0 * x / 399; });
  const Placement pl = page(200, 100, 0);
  const Drawing d = hatch_drawing(img, HatchParams{}, pl);
  // 16 strips: a band is 4 strips wide (2 at the ends), so strips 5 apart lie in different bands.
  const int n = 16;
  const auto len = length_per_strip(d, 0, 200, n);
  const double strip_area = 200.0 / n * 100;
  std::vector<double> per_mm2;
  for (double l : len) per_mm2.push_back(l / strip_area);
  for (int s = 0; s < n; ++s) INFO("strip " << s << ": " << per_mm2[size_t(s)] << " mm of line per mm2");
  CAPTURE(per_mm2);
  // Within a band the same lines (up to where they fall), across bands clearly less ink.
  for (int s = 1; s < n; ++s) CHECK(per_mm2[size_t(s)] <= 1.03 * per_mm2[size_t(s - 1)]);
  for (int s = 5; s < n; ++s) CHECK(per_mm2[size_t(s)] < 0.9 * per_mm2[size_t(s - 5)]);
  CHECK(per_mm2.front() > 4 * per_mm2[size_t(n) - 3]);
  // The darkest strip (mean darkness 15/16) is nearly covered by a 0.3 mm pen: at least
  // 2 mm of line per mm2; the lightest (1/16) gets little or none.
  CHECK(per_mm2.front() >= 2.0);
  CHECK(per_mm2.back() < 0.2);
}

TEST_CASE("hatch: the directions' ink lays each band's mean darkness where the pen can", "[hatch]") {
  const Image img = grey_image(300, 200, [](int x, int) { return 255.0 * x / 299; });
  HatchParams p;
  const ToneMap t = tone_map(img, p, page(150, 100, 0));
  const auto dirs = directions(t, p, 0.3);
  REQUIRE(dirs.size() == 4);
  CHECK(dirs[0].angle_deg == 45);
  CHECK(dirs[1].angle_deg == 135);
  CHECK(dirs[2].angle_deg == 0);
  CHECK(dirs[3].angle_deg == 90);
  for (size_t b = 1; b < t.darkness.size(); ++b) {
    INFO("band " << b << ": photo " << t.darkness[b] << ", hatch " << band_darkness(dirs, b, 1));
    CHECK(band_darkness(dirs, b, 1) == Approx(t.darkness[b]).margin(0.01));
    CHECK(band_darkness(dirs, b, 2) < band_darkness(dirs, b, 1));  // the knob fades every band
  }
  CHECK(band_darkness(dirs, 0, 1) == 0);
}

TEST_CASE("hatch: a palette's greys and blacks share the directions light to dark, and still lay the tone", "[hatch]") {
  const Image img = grey_image(300, 200, [](int x, int) { return 255.0 * x / 299; });
  HatchParams p;
  p.pens = load_palette(test::example("pens/fineliner12.toml")).pens;
  const ToneMap t = tone_map(img, p, page(150, 100, 0));
  const auto dirs = directions(t, p, 0.3);
  REQUIRE(dirs.size() == 4);
  CHECK(dirs[0].pen.name == "grey");
  CHECK(dirs[1].pen.name == "grey");
  CHECK(dirs[2].pen.name == "black");
  CHECK(dirs[3].pen.name == "black");
  // A grey pen lays less darkness a line: its lines lie closer than a black pen's would.
  HatchParams black = p;
  black.pens.clear();
  CHECK(dirs[0].spacing_mm < directions(t, black, 0.4)[0].spacing_mm);
  for (size_t b = 1; b + 1 < t.darkness.size(); ++b) CHECK(band_darkness(dirs, b, 1) == Approx(t.darkness[b]).margin(0.01));
}

TEST_CASE("hatch: pure white gives no lines, with or without contours", "[hatch]") {
  const Image white = grey_image(120, 80, [](int, int) { return 255; });
  HatchParams p;
  CHECK(line_count(hatch_drawing(white, p, page(210, 297, 10))) == 0);
  p.contours = true;
  CHECK(line_count(hatch_drawing(white, p, page(210, 297, 10))) == 0);
}

TEST_CASE("hatch: every line stays inside the page's margins", "[hatch]") {
  const Image img = load_image(test::example("coffee.png"));
  for (const double margin : {0.0, 12.0}) {
    HatchParams p;
    p.contours = true;
    const Drawing d = hatch_drawing(img, p, page(210, 297, margin));
    size_t points = 0, outside = 0;
    for (const Layer& l : d.layers)
      for (const Polyline& pl : l.lines)
        for (const Vec2& q : pl.pts) {
          ++points;
          outside += q.x < margin - 1e-9 || q.x > 210 - margin + 1e-9 || q.y < margin - 1e-9 || q.y > 297 - margin + 1e-9;
        }
    INFO("margin " << margin << ": " << outside << " of " << points << " points outside");
    CHECK(points > 1000);
    CHECK(outside == 0);
  }
}

TEST_CASE("hatch: zig-zags join a region's lines and never leave it", "[hatch]") {
  // A U: two bars joined at the bottom; the gap between the bars is outside.
  Mask m{60, 60, std::vector<uint8_t>(3600, 0)};
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 60; ++x) m.in[size_t(y) * 60 + x] = (x < 20 || x >= 40 || y >= 45) ? 1 : 0;
  for (const double angle : {0.0, 45.0, 90.0, 135.0}) {
    const auto strokes = hatch_mask(m, LineSet{angle, 3, 10});
    size_t segments = 0;
    for (const auto& s : strokes) {
      REQUIRE(s.size() >= 2);
      for (size_t i = 1; i < s.size(); ++i, ++segments)
        for (int k = 0; k <= 20; ++k) {  // every segment, lines and links, inside the U up to a cell
          const double f = k / 20.0;
          const Vec2 q{s[i - 1].x + f * (s[i].x - s[i - 1].x), s[i - 1].y + f * (s[i].y - s[i - 1].y)};
          INFO("angle " << angle << " point " << q.x << "," << q.y);
          REQUIRE((q.x < 21 || q.x >= 39 || q.y >= 44));
          if (i % 2 == 1) REQUIRE(m.inside(q.x, q.y));  // the hatch lines themselves strictly inside
        }
    }
    INFO("angle " << angle << ": " << strokes.size() << " strokes, " << segments << " segments");
    CHECK(strokes.size() <= 6);  // the pen lifts a handful of times, not once a line
    CHECK(segments > 30);
  }
  // A plain square: one stroke.
  Mask sq{40, 40, std::vector<uint8_t>(1600, 1)};
  CHECK(hatch_mask(sq, LineSet{45, 2, 10}).size() == 1);
}

TEST_CASE("hatch: a large region's lines are the same on 1 and 3 threads", "[hatch][threads]") {
  // Enough samples for the lines' runs to be found on several threads: blobs and holes.
  const int W = 900, H = 700;
  Mask m{W, H, std::vector<uint8_t>(size_t(W) * H, 0)};
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      m.in[size_t(y) * W + x] = std::sin(x * 0.031) * std::cos(y * 0.047) + 0.3 * std::sin((x + y) * 0.11) > 0.1 ? 1 : 0;
  for (const double angle : {0.0, 22.5, 90.0, 135.0}) {
    const LineSet set{angle, 2.5, 10};
    set_thread_count(1);
    const auto one = hatch_mask(m, set);
    set_thread_count(3);
    const auto three = hatch_mask(m, set);
    set_thread_count(0);
    INFO("angle " << angle);
    REQUIRE(one.size() > 100);
    REQUIRE(three.size() == one.size());
    bool same = true;
    for (size_t k = 0; k < one.size() && same; ++k) {
      same = one[k].size() == three[k].size();
      for (size_t i = 0; same && i < one[k].size(); ++i) same = one[k][i].x == three[k][i].x && one[k][i].y == three[k][i].y;
    }
    CHECK(same);
  }
}

TEST_CASE("hatch: the same input gives the same drawing", "[hatch]") {
  const Image img = load_image(test::example("horse.png"));
  HatchParams p;
  p.contours = true;
  const Drawing a = hatch_drawing(img, p, page(210, 297, 10)), b = hatch_drawing(img, p, page(210, 297, 10));
  REQUIRE(a.layers.size() == b.layers.size());
  for (size_t i = 0; i < a.layers.size(); ++i) {
    REQUIRE(a.layers[i].lines.size() == b.layers[i].lines.size());
    for (size_t k = 0; k < a.layers[i].lines.size(); ++k) CHECK(a.layers[i].lines[k].pts == b.layers[i].lines[k].pts);
  }
  test::TempDir t;
  const std::string base = "hatch " + test::example("coffee.png") + " --time 20min --quiet -o ";
  REQUIRE(test::run_cli(base + t.file("a.svg")).exit_code == 0);
  REQUIRE(test::run_cli(base + t.file("b.svg")).exit_code == 0);
  CHECK(test::read_file(t.file("a.svg")) == test::read_file(t.file("b.svg")));
}

TEST_CASE("hatch: the planned plot fits --time and uses it", "[hatch][budget][cli]") {
  test::TempDir t;
  for (const char* img : {"coffee.png", "horse.png"})
    for (const auto& [time, budget] : {std::pair{"15min", 900.0}, std::pair{"1h", 3600.0}}) {
      const auto r = test::run_cli("hatch " + test::example(img) + " -o " + t.file("h.svg") + " --time " + time + " --json");
      INFO(img << " " << time << "\n" << r.err);
      REQUIRE(r.exit_code == 0);
      const auto j = nlohmann::json::parse(r.out);
      const double planned = j["plan"]["total"]["seconds"].get<double>();
      INFO("planned " << planned << " s, knob " << j["budget"]["knob"] << ", runs " << j["budget"]["runs"]);
      CHECK(planned <= budget);
      if (!j["budget"]["finest"].get<bool>()) CHECK(planned >= 0.8 * budget);
      CHECK(j["command"] == "hatch");
    }
}

TEST_CASE("hatch: bad parameters are one error line and a non-zero exit", "[hatch][cli][bad-input]") {
  test::TempDir t;
  const std::string out = t.file("x.svg");
  for (const char* bad : {"--spacing -1", "--spacing nan", "--spacing 0", "--levels 0", "--levels 10", "--blur -2mm",
                          "--link inf", "--angle 1000", "--spacing 2furlongs", "--pens /no/such.toml"}) {
    const auto r = test::run_cli("hatch " + test::example("horse.png") + " -o " + out + " " + bad);
    INFO(bad << ": exit " << r.exit_code << ", stderr: " << r.err);
    CHECK(r.exit_code != 0);
    CHECK(r.exit_code < 64);
    CHECK(test::count_lines(r.err) == 1);
    CHECK(r.err.find("--") != std::string::npos);  // names the option
    CHECK_FALSE(std::filesystem::exists(out));
  }
  HatchParams none;
  none.levels = 0;
  CHECK_THROWS_AS(hatch_drawing(grey_image(8, 8, [](int, int) { return 0; }), none, Placement{}), UserError);
}
