#include <catch2/catch.hpp>
#include <tinyxml2.h>

#include <cmath>

#include "methods/stipple/stipple.hpp"
#include "plan/planner.hpp"
#include "svg/planned_svg.hpp"
#include "svg/svg_document.hpp"
#include "svg/svg_reader.hpp"
#include "svg/svg_writer.hpp"
#include "test_util.hpp"
#include "util/rng.hpp"
#include "util/threads.hpp"

using namespace stipplot;

TEST_CASE("SVG output parses back: mm units, viewBox, one Inkscape layer per pen, non-plotting paper",
          "[svg]") {
  Image img = test::grey_lines_image(64, 48);
  StippleParams p;
  p.method = StippleMethod::Binary;
  p.a_b = p.a_w = 1;
  p.b_b = p.b_w = 5;
  Placement pl;
  pl.page = parse_page("A5");
  Drawing d = stipple(img, p, pl);
  test::TempDir t;
  write_svg(d, t.file("o.svg"));

  tinyxml2::XMLDocument doc;
  REQUIRE(doc.LoadFile(t.file("o.svg").c_str()) == tinyxml2::XML_SUCCESS);
  auto* svg = doc.RootElement();
  REQUIRE(std::string(svg->Name()) == "svg");
  CHECK(std::string(svg->Attribute("width")) == "148mm");
  CHECK(std::string(svg->Attribute("height")) == "210mm");
  CHECK(std::string(svg->Attribute("viewBox")) == "0 0 148 210");

  int layers = 0, paper = 0;
  size_t circles = 0;
  for (auto* g = svg->FirstChildElement("g"); g; g = g->NextSiblingElement("g")) {
    REQUIRE(g->Attribute("inkscape:groupmode", "layer"));
    std::string label = g->Attribute("inkscape:label");
    if (label.rfind('%', 0) == 0) {
      ++paper;
      auto* rect = g->FirstChildElement("rect");
      REQUIRE(rect);
      CHECK(std::string(rect->Attribute("fill")) == "#808080");  // grey paper for binary
      CHECK(std::string(g->Attribute("class")) == "non-plotting");
      continue;
    }
    ++layers;
    for (auto* c = g->FirstChildElement("circle"); c; c = c->NextSiblingElement("circle")) {
      double cx = c->DoubleAttribute("cx"), cy = c->DoubleAttribute("cy");
      REQUIRE(cx >= 0);
      REQUIRE(cx <= 148);
      REQUIRE(cy >= 0);
      REQUIRE(cy <= 210);
      ++circles;
    }
  }
  CHECK(paper == 1);
  CHECK(layers == 2);
  CHECK(circles == d.primitive_count());
}

TEST_CASE("numbers are written compactly and exactly to the micrometre", "[svg]") {
  CHECK(format_number(1.0, 3) == "1");
  CHECK(format_number(1.23456, 3) == "1.235");
  CHECK(format_number(-0.0001, 3) == "0");
  CHECK(format_number(210, 3) == "210");
}

TEST_CASE("a failed write leaves no file behind", "[svg]") {
  Drawing d;
  CHECK_THROWS(write_svg(d, "/nonexistent-dir/x.svg"));
  CHECK(!std::filesystem::exists("/nonexistent-dir/x.svg"));
}

TEST_CASE("a line of more points than an element holds is written as consecutive pieces, and planned as one stroke again",
          "[svg]") {
  Drawing d;
  d.page = Page{200, 200};
  Layer l;
  l.pen = Pen{"black", colors::black, 0.3};
  Polyline spiral;
  for (int i = 0; i < 2500; ++i) {
    const double a = 0.05 * i, r = 5 + 0.03 * i;
    spiral.pts.push_back({100 + r * std::cos(a), 100 + r * std::sin(a)});
  }
  l.lines.push_back(spiral);
  d.layers.push_back(l);
  test::TempDir t;
  write_svg(d, t.file("s.svg"));
  const Drawing back = read_svg(t.file("s.svg"));
  REQUIRE(back.layers.size() == 1);
  // 2,500 points: 1,000 + 1,000 + 502 (each piece starts where the last ended).
  REQUIRE(back.layers[0].lines.size() == 3);
  CHECK(back.layers[0].lines[0].pts.size() == kMaxElementPoints);
  CHECK(back.layers[0].lines[2].pts.size() == 2500 - 2 * (kMaxElementPoints - 1));
  CHECK(back.layers[0].lines[0].pts.back().x == back.layers[0].lines[1].pts.front().x);
  PlanOptions po;
  const Plan plan = plan_drawing(back, po);
  REQUIRE(plan.layers.size() == 1);
  CHECK(plan.layers[0].strokes.size() == 1);
  CHECK(plan.layers[0].strokes[0].pts.size() == 2500);
}

TEST_CASE("a large drawing and its plan are written as the same text on 1 and 3 threads", "[svg][threads]") {
  // Enough points for the numbers to be formatted on several threads (batches of 256
  // elements): long lines split into elements, short lines, and in the plan dots between
  // them (a dot ends a run of lines).
  Drawing d;
  d.page = Page{300, 300};
  Layer l;
  l.pen = Pen{"black", colors::black, 0.3};
  Rng rng(3);
  for (int k = 0; k < 900; ++k) {
    Polyline pl;
    const int n = k % 50 == 0 ? 9000 : k % 7 == 0 ? 1 : 2 + k % 300;
    for (int i = 0; i < n; ++i) pl.pts.push_back({10 + rng.uniform() * 280, 10 + rng.uniform() * 280});
    l.lines.push_back(pl);
  }
  d.layers.push_back(l);
  Plan plan;
  plan.page = d.page;
  plan.layers.resize(1);
  plan.layers[0].pen = l.pen;
  for (const auto& pl : l.lines) plan.layers[0].strokes.push_back(Stroke{pl.pts});
  set_thread_count(1);
  const std::string one = svg_string(d), plan_one = planned_svg_string(plan);
  set_thread_count(3);
  const std::string three = svg_string(d), plan_three = planned_svg_string(plan);
  // A coordinate that is not a number fails the write on the threads too, as on one.
  d.layers[0].lines[600].pts[5].x = std::nan("");
  CHECK_THROWS_AS(svg_string(d), std::logic_error);
  set_thread_count(0);
  CHECK(one.size() > 2'000'000);
  CHECK(one == three);
  CHECK(plan_one == plan_three);
  CHECK(plan_one.find("<circle") != std::string::npos);
}
