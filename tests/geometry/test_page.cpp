#include <catch2/catch.hpp>

#include "geometry/color.hpp"
#include "geometry/page.hpp"
#include "methods/placement.hpp"
#include "util/error.hpp"
#include "util/units.hpp"

using namespace stipplot;

TEST_CASE("page names and custom sizes parse", "[page]") {
  auto a4 = parse_page("A4");
  CHECK(a4.width_mm == 210);
  CHECK(a4.height_mm == 297);
  CHECK(parse_page("letter").width_mm == Approx(215.9));
  auto c = parse_page("300x200mm");
  CHECK(c.width_mm == 300);
  CHECK(c.height_mm == 200);
  CHECK(parse_page("11x8.5in").width_mm == Approx(279.4));
  CHECK_THROWS_AS(parse_page("B7"), UserError);
  CHECK_THROWS_WITH(parse_page("0x100mm"), Catch::Contains("positive"));
  CHECK_THROWS_WITH(parse_page("10x10furlong"), Catch::Contains("furlong"));
  CHECK_THROWS_AS(parse_page("10x"), UserError);
  CHECK(parse_page(" 100 x 50 cm").height_mm == Approx(500));
}

TEST_CASE("fit-with-margin maps the image inside the margins, centred", "[page]") {
  // 400x200 px on A4 portrait with 10 mm margins: width-limited, 190/400 mm per px
  PageTransform t(400, 200, parse_page("A4"), 10, false);
  CHECK(t.page_w() == 210);
  CHECK(t.mm_per_px() == Approx(190.0 / 400));
  Vec2 tl = t.map(0, 0), br = t.map(400, 200);
  CHECK(tl.x == Approx(10));
  CHECK(br.x == Approx(200));
  CHECK((tl.y + br.y) / 2 == Approx(297 / 2.0));  // centred vertically
  Vec2 back = t.unmap(t.map(123, 45));
  CHECK(back.x == Approx(123));
  CHECK(back.y == Approx(45));
}

TEST_CASE("landscape turns the long side horizontal", "[page]") {
  PageTransform t(400, 200, parse_page("A4"), 10, true);
  CHECK(t.page_w() == 297);
  CHECK(t.page_h() == 210);
  // height-limited now? 277/400 = 0.6925 vs 190/200 = 0.95 -> width-limited
  CHECK(t.mm_per_px() == Approx(277.0 / 400));
  CHECK_THROWS_WITH(PageTransform(10, 10, parse_page("A4"), 150, false), Catch::Contains("margin"));
  CHECK_THROWS_WITH(PageTransform(10, 10, parse_page("A4"), -1, false), Catch::Contains("margin"));
}

TEST_CASE("lengths in mm or pixels", "[page]") {
  CHECK(Length::parse("0", "--x").to_mm(2) == 0);  // 0 is 0 in any unit
  CHECK(Length::parse("0.4mm", "--x").to_mm(2) == Approx(0.4));
  CHECK(Length::parse("1.5px", "--x").to_mm(2) == Approx(3));
  CHECK_THROWS_WITH(Length::parse("-1", "--dot-size"), Catch::Contains("--dot-size"));
  CHECK_THROWS_WITH(Length::parse("nan", "--dot-size"), Catch::Contains("--dot-size"));
  CHECK_THROWS_AS(Length::parse("px", "--dot-size"), UserError);
}

TEST_CASE("lengths - one grammar for paper units and image pixels", "[page][units]") {
  CHECK(Length::parse("2cm", "--x").to_mm(3) == Approx(20));
  CHECK(Length::parse("0.5in", "--x").to_mm(3) == Approx(12.7));
  CHECK(Length::parse("72pt", "--x").to_mm(3) == Approx(25.4));
  CHECK(Length::parse(" 1.5 PX ", "--x").to_mm(2) == Approx(3));
  CHECK(Length::parse("3", "--radius", Length::Bare::px).in_px);
  CHECK(Length::parse("3px", "--radius", Length::Bare::px).in_px);
  CHECK_FALSE(Length::parse("0.5mm", "--radius", Length::Bare::px).in_px);
  CHECK(Length::parse("0.4mm", "--x").value == 0.4);  // numbers exactly as written
  // A bare number could be either unit: refused, naming both readings.
  CHECK_THROWS_WITH(Length::parse("6", "-a"), "-a 6: a length needs a unit here: 6px (input pixels) or 6mm (on paper)");
  CHECK_THROWS_WITH(Length::parse(" 0.4 ", "--dot-size"), Catch::Contains("0.4px (input pixels) or 0.4mm"));
  CHECK_THROWS_WITH(Length::parse("3furlong", "--cell"), Catch::Contains("--cell"));
  CHECK_THROWS_AS(Length::parse("0x10", "--x"), UserError);  // no hex
  CHECK_THROWS_AS(Length::parse("inf", "--x"), UserError);
  CHECK(parse_paper_mm("10", "--margin") == 10);
  CHECK(parse_paper_mm("1.5cm", "--margin") == Approx(15));
  // on paper a px is CSS's 1/96 in, as in SVG files
  CHECK(parse_paper_mm("96px", "--margin") == Approx(25.4));
  CHECK_THROWS_WITH(parse_paper_mm("3furlong", "--margin"), Catch::Contains("--margin"));
  CHECK_THROWS_WITH(parse_paper_mm("-1", "--margin"), Catch::Contains("--margin"));
  CHECK_THROWS_AS(parse_paper_mm("", "--margin"), UserError);
  // page sizes read their numbers and unit with the same grammar
  CHECK(parse_page("30x20cm").width_mm == Approx(300));
  CHECK(parse_page("720x360pt").height_mm == Approx(127));
  CHECK(parse_page("960x480px").width_mm == Approx(254));
  CHECK_THROWS_WITH(parse_page("300x200furlong"), Catch::Contains("300x200furlong"));
}

TEST_CASE("colours parse from hex, rgb() and names", "[color]") {
  CHECK(Color::parse("#ff8000") == Color{255, 128, 0});
  CHECK(Color::parse("#f80") == Color{255, 136, 0});
  CHECK(Color::parse("rgb(1, 2, 3)") == Color{1, 2, 3});
  CHECK(Color::parse("Black") == colors::black);
  CHECK(Color{16, 32, 255}.hex() == "#1020ff");
  CHECK_THROWS_AS(Color::parse("#12345"), UserError);
  CHECK_THROWS_AS(Color::parse("rgb(300,0,0)"), UserError);
  CHECK_THROWS_AS(Color::parse("blurple"), UserError);
}
