// Connected stippling (stipple --connect, TSP art after Kaplan & Bosch 2005): the points
// joined by the planner's tour and drawn as one line, lifted only over light ground; the
// line's ink lays the tone; the plot fits the budget.
#include <catch2/catch.hpp>
#include <cmath>
#include <nlohmann/json.hpp>

#include "methods/stipple/connect.hpp"
#include "util/threads.hpp"
#include "cli_json.hpp"
#include "test_util.hpp"

using namespace stipplot;

namespace {

using test::run_json;

// A grey image: `fill(x, y)` gives each pixel's level.
template <class F>
Image grey_image(int w, int h, F fill) {
  Image img;
  img.width = w, img.height = h;
  img.rgb.resize(img.pixels() * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) img.rgb[(static_cast<size_t>(y) * w + x) * 3 + c] = fill(x, y);
  return img;
}

Placement square_page(double side_mm) {
  Placement pl;
  pl.page = {side_mm, side_mm};
  pl.margin_mm = 0;
  return pl;
}

double line_length(const Drawing& d) {
  double len = 0;
  for (const Layer& l : d.layers)
    for (const Polyline& pl : l.lines)
      for (size_t i = 1; i < pl.pts.size(); ++i) len += std::hypot(pl.pts[i].x - pl.pts[i - 1].x, pl.pts[i].y - pl.pts[i - 1].y);
  return len;
}

}  // namespace

TEST_CASE("a connected uniform grey lays its tone with the line", "[stipple][connect]") {
  // Light tones, where neighbouring lines barely overlap: the line's ink (pen x length per
  // area) is the tone asked for, within 12 %, with no curve (kConnectInk is measured here).
  for (double u : {0.08, 0.15, 0.25}) {
    const Image img = grey_image(64, 64, [&](int, int) { return static_cast<uint8_t>(std::lround(255 * (1 - u))); });
    const Placement pl = square_page(60);
    const StippleCanvas c = prepare_stipple(img, StippleMethod::Gray, pl, 0.1);
    ConnectParams p;
    ConnectStats st;
    const Drawing d = connect_on_page(c, p, &st);
    const double area = 60.0 * 60.0;
    const double ink = 0.3 * line_length(d) / area;
    const double r = connect_spacing_mm(u, 0.3, p);
    INFO("u " << u << ": " << st.points << " points, " << st.lines << " lines, " << st.lifted << " lifted; ink "
              << ink << "; c = L / sqrt(N A) = " << line_length(d) / std::sqrt(st.points * area)
              << "; ink x r / pen = " << ink * r / 0.3);
    CHECK(ink == Approx(u).epsilon(0.12));
    // A uniform ground lifts almost nowhere: one line, or nearly.
    CHECK(st.lifted <= st.points / 200 + 1);
    // What the raster sees agrees with the pen x length estimate (overlaps are few).
    const LevelCoverage cov = measured_line_coverage(c, d);
    double cells = 0, covered = 0;
    for (int v = 0; v < 256; ++v) cells += cov.cells[v], covered += cov.covered[v];
    CHECK(covered / cells == Approx(ink).epsilon(0.15));
  }
}

TEST_CASE("no drawn link crosses light ground: two dark fields apart are drawn apart", "[stipple][connect]") {
  // Two dark squares on white paper, a 20 mm white band between them, and a grey
  // ramp below: every drawn segment obeys the lift rule, and none joins the squares.
  const Image img = grey_image(200, 100, [](int x, int y) -> uint8_t {
    if (y >= 60) return static_cast<uint8_t>(40 + x);  // a ramp, dark to light
    if (y >= 10 && y < 50 && ((x >= 10 && x < 80) || (x >= 120 && x < 190))) return 60;
    return 255;
  });
  Placement pl;
  pl.page = {100, 50};
  pl.margin_mm = 0;
  const StippleCanvas c = prepare_stipple(img, StippleMethod::Gray, pl, 0.1);
  ConnectParams p;
  ConnectStats st;
  const Drawing d = connect_on_page(c, p, &st);
  const pds::RadiusTable radius = connect_radii(c, p);
  REQUIRE(st.points > 500);
  size_t segments = 0;
  for (const Polyline& l : d.layers[0].lines)
    for (size_t i = 1; i < l.pts.size(); ++i) {
      const Vec2 a = l.pts[i - 1], b = l.pts[i];
      ++segments;
      CHECK_FALSE(connect_link_lifted(c, radius, p, a, b));
      const bool a_left = a.x < 50 && a.y < 30, b_left = b.x < 50 && b.y < 30;
      const bool a_right = a.x >= 50 && a.y < 30, b_right = b.x >= 50 && b.y < 30;
      if ((a_left && b_right) || (a_right && b_left)) FAIL("a link joins the two squares across the white band");
      // Nothing drawn reaches into the white paper more than a link's length from ink.
      CHECK_FALSE((a.y < 30 && a.y > 26 && b.y < 30 && b.y > 26));
    }
  // Lifted where it must, joined elsewhere: far fewer lines than points.
  CHECK(st.lines + st.touches < st.points / 20);
  CHECK(segments == st.links);
  // The rule itself: a link straight across the band, or far longer than the spacing, lifts.
  CHECK(connect_link_lifted(c, radius, p, {38, 15}, {62, 15}));
  CHECK(connect_link_lifted(c, radius, p, {10, 10}, {30, 20}));
  CHECK_FALSE(connect_link_lifted(c, radius, p, {20, 15}, {20.5, 15.2}));
}

TEST_CASE("connected stippling is deterministic for a seed and refuses multi-pen methods", "[stipple][connect]") {
  const Image img = grey_image(80, 60, [](int x, int y) { return static_cast<uint8_t>((x * 3 + y * 2) % 256); });
  Placement pl;
  pl.page = {80, 60};
  pl.margin_mm = 0;
  const StippleCanvas c = prepare_stipple(img, StippleMethod::Gray, pl, 0.15);
  ConnectParams p;
  p.seed = 7;
  const Drawing a = connect_on_page(c, p), b = connect_on_page(c, p);
  REQUIRE(a.layers[0].lines.size() == b.layers[0].lines.size());
  for (size_t i = 0; i < a.layers[0].lines.size(); ++i) CHECK(a.layers[0].lines[i].pts == b.layers[0].lines[i].pts);
  const StippleCanvas bin = prepare_stipple(img, StippleMethod::Binary, pl, 0.15);
  CHECK_THROWS_WITH(connect_on_page(bin, p), Catch::Contains("-m gray, random or negative"));
  p.lift_length = 0.5;
  CHECK_THROWS_WITH(connect_on_page(c, p), Catch::Contains("--lift-length"));
}

TEST_CASE("stipple --connect: far fewer pen lifts than the dot stipple, within the budget, the photo's tone",
          "[stipple][connect][cli][slow]") {
  test::TempDir t;
  const std::string img = std::string(STIPPLOT_SHARED_DIR) + "/images/coffee.png";
  const std::string page = " --profile grbl-servo --page 297x210mm --margin 10";
  for (const char* time : {"15min", "1h"}) {
    const double budget = std::string(time) == "15min" ? 900 : 3600;
    const auto dots = run_json("stipple " + img + " --dots -o " + t.file("d.svg") + page + " --time " + time + " --measure");
    const auto line = run_json("stipple " + img + " --connect -o " + t.file("c.svg") + page + " --time " + time +
                               " --measure");
    const double planned = line["plan"]["total"]["seconds"].get<double>();
    const double lifts = line["plan"]["total"]["pen_lifts"].get<double>();
    const double dot_lifts = dots["plan"]["total"]["pen_lifts"].get<double>();
    INFO(time << ": planned " << planned << " s, knob " << line["budget"]["knob"] << ", lifts " << lifts << " vs "
              << dot_lifts << " dots; connect " << line["connect"].dump());
    CHECK(planned <= budget);
    if (!line["budget"]["finest"].get<bool>()) CHECK(planned >= 0.8 * budget);
    CHECK(lifts < 0.2 * dot_lifts);
    // The hour spent on a line rather than on a few thousand filled discs: a truer
    // picture seen from arm's length (coffee: SSIM at 1 mm 0.63 against 0.48 at 15 min, 0.79 against 0.38 at 1 h).
    INFO("SSIM at 1 mm " << line["ssim_view"] << " vs dots " << dots["ssim_view"]);
    CHECK(line["ssim_view"].get<double>() > dots["ssim_view"].get<double>() + 0.1);
    CHECK(line["tone_r_view"].get<double>() >= 0.9);
  }
  // The default at 1 h on coffee is the line (its whole tone needs more than half an hour
  // more, and the hour's dots would be discs over 3 mm), at 4 h the dots (2 mm, fine enough);
  // --law linear is always the paper's dots.
  const auto auto1 = run_json("stipple " + img + " -o " + t.file("a.svg") + page + " --time 1h");
  CHECK(auto1["style"] == "connect");
  CHECK(auto1["style_choice"]["connect_full_tone_s"].get<double>() > 1800);
  CHECK(auto1["style_choice"]["dots_max_dot_mm"].get<double>() > 3);
  const auto auto4 = run_json("stipple " + img + " -o " + t.file("a.svg") + page + " --time 4h");
  CHECK(auto4["style"] == "dots");
  // The prediction the choice uses is the dots the search then draws (within 10 %).
  const auto dots4 = run_json("stipple " + img + " --dots -o " + t.file("a.svg") + page + " --time 4h");
  CHECK(auto4["style_choice"]["dots_max_dot_mm"].get<double>() ==
        Approx(dots4["max_dot_mm"].get<double>()).epsilon(0.1));
  CHECK(run_json("stipple " + img + " --law linear -o " + t.file("a.svg") + page)["style"] == "dots");
  // With the time for the whole tone, the line lays it: blurred at 1 mm, the drawing's
  // mean grey within 0.06 of the photo's, and the tone error small.
  const auto full = run_json("stipple " + img + " --connect -o " + t.file("f.svg") + page + " --time 4h --measure");
  INFO(full.dump());
  CHECK(full["budget"]["tone_share"].get<double>() >= 0.99);
  CHECK(full["tone_err_view"].get<double>() <= 0.08);
  CHECK(full["tone_r_view"].get<double>() >= 0.9);
}

TEST_CASE("stipple --connect: bad parameters get one line and exit 1", "[stipple][connect][cli]") {
  test::TempDir t;
  const std::string img = test::example("horse.png");
  const std::string out = " -o " + t.file("x.svg");
  const std::pair<const char*, const char*> cases[] = {
      {"--connect -m binary", "-m gray, random or negative"},
      {"--connect -m cmyk", "-m gray, random or negative"},
      {"--connect --law linear", "--law tone"},
      {"--connect -a 2px", "--law"},
      {"--connect --max-dot 2mm", "--max-dot"},
      {"--connect --lift-length 0.5", "--lift-length"},
      {"--connect --lift-tone 1.5", "--lift-tone"},
      {"--dots --lift-tone 0.3", "--connect"},
      {"--connect --dots", "give one"},
      {"-m binary --lift-length 4", "--connect"},
      {"--connect --dot-size 1mm", "--dot-size"},
  };
  for (const auto& [opts, word] : cases) {
    const auto r = test::run_cli("stipple " + img + out + " " + opts);
    INFO(opts << ": " << r.err);
    CHECK(r.exit_code == 1);
    CHECK(test::count_lines(r.err) == 1);
    CHECK(r.err.find(word) != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(t.file("x.svg")));
  }
}

TEST_CASE("the coverage a drawing's lines lay is measured the same on 1 and 3 threads, as much as they cover", "[stipple][connect][threads]") {
  // 60 mm square at a 0.05 mm cell: 2,400 x 2,400 raster cells, enough for the bands to
  // run in parallel. A grey ramp; 200 horizontal lines 0.3 mm wide, 0.25 mm apart (they
  // overlap), and a row of 1 mm dots below them.
  const Image img = grey_image(120, 120, [](int x, int) { return static_cast<uint8_t>(2 * x); });
  const Placement pl = square_page(60);
  const StippleCanvas c = prepare_stipple(img, StippleMethod::Gray, pl, 0.05);
  Drawing d;
  d.page = {60, 60};
  Layer l;
  l.pen = Pen{"black", colors::black, 0.3};
  for (int i = 0; i < 200; ++i) l.lines.push_back(Polyline{{{5, 5 + 0.25 * i}, {55, 5 + 0.25 * i + 0.01 * i}}});
  for (int i = 0; i < 40; ++i) l.dots.push_back(Dot{{5 + 1.25 * i, 58}, 1.0});
  d.layers.push_back(l);
  auto measure = [&](int threads) {
    set_thread_count(threads);
    const LevelCoverage cov = measured_line_coverage(c, d);
    set_thread_count(0);
    return cov;
  };
  const LevelCoverage one = measure(1), three = measure(3);
  double cells = 0, covered = 0;
  for (int v = 0; v < 256; ++v) {
    CHECK(one.cells[v] == three.cells[v]);
    CHECK(one.covered[v] == three.covered[v]);
    cells += one.cells[v], covered += one.covered[v];
  }
  CHECK(cells == 2400.0 * 2400.0);
  // The lines' band (50 mm by ~52 mm, solid where they overlap) and the dots' discs.
  const double want = (50 * (0.25 * 199 + 0.3 + 0.01 * 199 / 2) + 40 * M_PI * 0.25) / (60.0 * 60.0);
  CHECK(covered / cells == Approx(want).epsilon(0.03));
}
