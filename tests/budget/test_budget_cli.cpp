// The plot-time budget as a user meets it: every method command plans its drawing to fit
// --time on the profile (planned time <= the budget, and >= 0.8 of it where the image can
// use it), and the same page and pen give the same drawing whatever the input's size.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "cli/method_command.hpp"
#include "preview/preview.hpp"
#include "svg/svg_reader.hpp"
#include "cli_json.hpp"
#include "test_util.hpp"

namespace {


using test::run_json;

// The input resampled by `scale` (area averaging down, cubic up), written as PNG.
std::string scaled_copy(const test::TempDir& t, const std::string& src, double scale, const std::string& name) {
  const stipplot::Image in = stipplot::load_image(src);
  stipplot::Image out;
  out.width = static_cast<int>(in.width * scale);
  out.height = static_cast<int>(in.height * scale);
  out.rgb.resize(out.pixels() * 3);
  const cv::Mat a(in.height, in.width, CV_8UC3, const_cast<uint8_t*>(in.rgb.data()));
  cv::Mat b(out.height, out.width, CV_8UC3, out.rgb.data());
  cv::resize(a, b, b.size(), 0, 0, scale < 1 ? cv::INTER_AREA : cv::INTER_CUBIC);
  stipplot::write_png(out, t.file(name));
  return t.file(name);
}

}  // namespace

TEST_CASE("the planned plot fits the budget and uses it: 15 min, 1 h, 4 h on two profiles", "[budget][cli][slow]") {
  test::TempDir t;
  const std::string img = test::example("coffee.png");
  for (const char* profile : {"grbl-servo", "hp7475a-a4"}) {
    for (const char* time : {"15min", "1h", "4h"}) {
      const double budget = std::string(time) == "15min" ? 900 : std::string(time) == "1h" ? 3600 : 14400;
      const auto j = run_json("stipple " + img + " -o " + t.file("b.svg") + " --profile " + profile + " --time " + time);
      const double planned = j["plan"]["total"]["seconds"].get<double>();
      INFO(profile << " " << time << ": planned " << planned << " s, knob " << j["budget"]["knob"]);
      CHECK(planned <= budget);
      // The finest drawing (every dot one pen touch at the spacing of the tone) is all
      // an image can use: below that the budget must be used.
      if (!j["budget"]["finest"].get<bool>()) CHECK(planned >= 0.8 * budget);
      CHECK(j["budget"]["seconds"].get<double>() == budget);
    }
  }
}

TEST_CASE("a written grbl job fits the budget with the wire's pace", "[budget][cli][slow]") {
  // A tree's rounded loops are short lines, more than 115,200 baud carry at speed: timed
  // from its written lines the job came out at 66.5 min for an hour's budget. The job's
  // own time decides; the drawing is made again below the budget when it is over.
  test::TempDir t;
  const auto j = run_json("tree " + test::example("coffee.png") + " -o " + t.file("tree.gcode") +
                          " --profile grbl-servo --time 1h");
  const double job = j["plan"]["total"]["seconds"].get<double>();
  INFO(j["budget"].dump());
  CHECK(job <= 3600);
  CHECK(job >= 0.9 * 3600);
  // The studio's way: an SVG for the profile, exported to its job afterwards.
  const auto svg = run_json("tree " + test::example("coffee.png") + " -o " + t.file("tree.svg") +
                            " --profile grbl-servo --time 1h");
  const auto exported = run_json("export " + t.file("tree.svg") + " -o " + t.file("exported.gcode") + " --profile grbl-servo");
  const double exported_s = exported["plan"]["total"]["seconds"].get<double>();
  CHECK(exported_s <= 3600);
  CHECK(exported_s == Approx(svg["plan"]["total"]["seconds"].get<double>()).epsilon(0.01));
}

TEST_CASE("the same page and pen give the same marks whatever the input's resolution", "[budget][cli][slow]") {
  test::TempDir t;
  const std::string img = test::example("coffee.png");
  const std::string quarter = scaled_copy(t, img, 0.25, "q.png"), four = scaled_copy(t, img, 4, "x4.png");
  const std::string opts = " -o " + t.file("r.svg") + " --time 30min";
  // Marks: a sketch's strokes before they are linked into scribbles; a tree's points (how
  // its trails split depends on near ties among the Euclidean tree's edges: 1,370-1,650
  // trails for 17,300-18,200 points).
  auto marks = [](const nlohmann::json& j) {
    if (j.value("command", "") == "tree") return j["points"].get<double>();
    return (j.contains("linked") ? j["linked"]["strokes"] : j["primitives"]).get<double>();
  };
  for (const char* method : {"stipple --dots", "sketch", "pointillism", "tree"}) {
    const auto base = run_json(std::string(method) + " " + img + opts);
    const double n = marks(base);
    for (const std::string& other : {quarter, four}) {
      const auto j = run_json(std::string(method) + " " + other + opts);
      INFO(method << " " << other << ": " << marks(j) << " marks against " << n);
      // A linked sketch's time also depends on how many links its probability field allows,
      // and a quarter-size photo's field, upsampled to the grid, is smoother: 8 % more marks.
      // A tree's points are spaced little more than a cell apart at its weight's spacing,
      // where the smoother upsampled field packs 5-8 % more of them into the same time.
      const bool looser = j.contains("linked") || j.value("command", "") == "tree";
      CHECK(std::abs(marks(j) - n) <= (looser ? 0.10 : 0.05) * n);
    }
  }
  // A connected drawing's marks are a few long lines: its points are what must agree.
  const auto base = run_json("stipple --connect " + img + opts);
  const double n = base["connect"]["points"].get<double>();
  for (const std::string& other : {quarter, four}) {
    const auto j = run_json("stipple --connect " + other + opts);
    INFO("stipple --connect " << other << ": " << j["connect"]["points"] << " points against " << n);
    CHECK(std::abs(j["connect"]["points"].get<double>() - n) <= 0.05 * n);
  }
}

TEST_CASE("sketch and pointillism fit the budget and use it: 15 min and 1 h on two profiles", "[budget][cli][slow]") {
  test::TempDir t;
  const std::string img = test::example("coffee.png");
  for (const char* method : {"sketch", "pointillism"}) {
    for (const char* profile : {"grbl-servo", "hp7475a-a4"}) {
      for (const char* time : {"15min", "1h"}) {
        const double budget = std::string(time) == "15min" ? 900 : 3600;
        const auto j = run_json(std::string(method) + " " + img + " -o " + t.file("b.svg") + " --profile " + profile +
                                " --time " + time);
        const double planned = j["plan"]["total"]["seconds"].get<double>();
        INFO(method << " " << profile << " " << time << ": planned " << planned << " s, knob " << j["budget"]["knob"]);
        CHECK(planned <= budget);
        if (!j["budget"]["finest"].get<bool>()) CHECK(planned >= 0.8 * budget);
        // Thinned evenly: the tone share is the share of marks kept.
        CHECK(j["budget"]["tone_share"].get<double>() == Approx(j["budget"]["knob"].get<double>()));
      }
    }
  }
}

TEST_CASE("every method's marks stay inside the image's rectangle with no margin", "[budget][cli]") {
  test::TempDir t;
  const std::string img = test::example("coffee.png");
  const stipplot::Image in = stipplot::load_image(img);
  // 60 x 60 mm, no margin: the image fills the width, its rectangle touches the page's edge.
  const double h = 60.0 * in.height / in.width, top = (60 - h) / 2, eps = 1e-6;
  auto outside = [&](stipplot::Vec2 p) { return p.x < -eps || p.x > 60 + eps || p.y < top - eps || p.y > top + h + eps; };
  for (const char* method : {"sketch", "pointillism", "stipple", "tree", "hatch"}) {
    const std::string opts = " --page 60x60mm --margin 0 --time 10min";
    // G-code: the writer refuses any point off the page.
    run_json(std::string(method) + " " + img + " -o " + t.file("c.gcode") + opts);
    run_json(std::string(method) + " " + img + " -o " + t.file("c.svg") + opts);
    const stipplot::Drawing d = stipplot::read_svg(t.file("c.svg"));
    size_t out = 0, marks = 0;
    for (const auto& l : d.layers) {
      for (const auto& pl : l.lines)
        for (const auto& p : pl.pts) out += outside(p), ++marks;
      for (const auto& c : l.circles) out += outside(c.c), ++marks;
      for (const auto& dot : l.dots) out += outside(dot.c), ++marks;
    }
    INFO(method << ": " << out << " of " << marks << " points outside");
    CHECK(marks > 0);
    CHECK(out == 0);
  }
}

TEST_CASE("thinning keeps the share k of every kind of mark spread evenly over the list", "[budget]") {
  stipplot::Drawing d;
  d.layers.resize(2);
  for (int i = 0; i < 1000; ++i) {
    d.layers[0].lines.push_back({{{double(i), 0}, {double(i), 1}}});
    d.layers[1].dots.push_back({{double(i), 0}, 0.3});
    d.layers[1].circles.push_back({{double(i), 0}, 1.0});
  }
  for (double k : {0.1, 0.37, 0.5, 0.9}) {
    const stipplot::Drawing t = stipplot::cli::thin_marks(d, k);
    REQUIRE(t.layers.size() == 2);
    INFO("k = " << k);
    CHECK(std::abs(double(t.layers[0].lines.size()) - 1000 * k) <= 2);
    CHECK(std::abs(double(t.layers[1].dots.size()) - 1000 * k) <= 2);
    CHECK(std::abs(double(t.layers[1].circles.size()) - 1000 * k) <= 2);
    // Every tenth of the list keeps its share (the golden-ratio sequence's low discrepancy).
    for (int tenth = 0; tenth < 10; ++tenth) {
      size_t n = 0;
      for (const auto& l : t.layers[0].lines) n += l.pts[0].x >= tenth * 100 && l.pts[0].x < (tenth + 1) * 100;
      CHECK(std::abs(double(n) - 100 * k) <= 3);
    }
  }
  CHECK(stipplot::cli::thin_marks(d, 1).primitive_count() == d.primitive_count());
  CHECK(stipplot::cli::thin_marks(d, 0).layers.empty());
}

TEST_CASE("tree fits the budget and uses it: wider spacing, not a thinned tree, on two profiles", "[budget][cli][slow]") {
  test::TempDir t;
  const std::string img = test::example("coffee.png");
  for (const char* profile : {"grbl-servo", "hp7475a-a4"}) {
    for (const char* time : {"10min", "1h"}) {
      const double budget = std::string(time) == "10min" ? 600 : 3600;
      const auto j = run_json("tree " + img + " -o " + t.file("t.svg") + " --profile " + profile + " --time " + time);
      const double planned = j["plan"]["total"]["seconds"].get<double>();
      INFO(profile << " " << time << ": planned " << planned << " s, knob " << j["budget"]["knob"]);
      CHECK(planned <= budget);
      if (!j["budget"]["finest"].get<bool>()) {
        CHECK(planned >= 0.8 * budget);
        CHECK(j["spacing_scale"].get<double>() > 1);  // the stipple radii grew
      }
      // Still one tree: a spanning tree of n points has n - 1 edges, those drawn and the
      // bridges over light ground the tone law leaves out.
      CHECK(j["trees"][0]["edges"].get<size_t>() + j["trees"][0]["bridges_left_out"].get<size_t>() + 1 ==
            j["points"].get<size_t>());
    }
  }
}
