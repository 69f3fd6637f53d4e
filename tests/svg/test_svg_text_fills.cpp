// The SVG reader's filled shapes (areas with their fill rule) and text drawn with the
// Hershey fonts: positions, anchors, spans, transforms, text on a path, tref, flowRoot.
#include <catch2/catch.hpp>

#include <cmath>

#include "svg/svg_reader.hpp"
#include "svg/text_layout.hpp"

using namespace stipplot;

namespace {

std::string page_svg(const std::string& body) {
  return R"~(<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="200mm" height="100mm" viewBox="0 0 200 100">)~" +
         body + "</svg>";
}

Drawing parse_text_svg(const std::string& svg) { return parse_svg(svg, "test.svg"); }

struct Box {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  void add(Vec2 p) {
    x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
  }
};

Box ink(const Drawing& d) {
  Box b;
  for (const auto& l : d.layers)
    for (const auto& pl : l.lines)
      for (const auto& p : pl.pts) b.add(p);
  return b;
}

}  // namespace

TEST_CASE("text: Hershey glyphs at the position and size the SVG gives", "[svg][text]") {
  // 'H' of futural: x 4..18, capitals 21 units high; a font size is 32 units
  Drawing d = parse_text_svg(page_svg(R"~(<text x="10" y="50" font-size="32" fill="black">H</text>)~"));
  REQUIRE(d.layers.size() == 1);
  CHECK(d.layers[0].lines.size() == 3);
  const Box b = ink(d);
  CHECK(b.x0 == Approx(14));
  CHECK(b.x1 == Approx(28));
  CHECK(b.y0 == Approx(29));
  CHECK(b.y1 == Approx(50));
  // anchors shift each chunk by its width (HH: 2 x 22 units)
  CHECK(ink(parse_text_svg(page_svg(R"~(<text x="100" y="50" font-size="32" text-anchor="middle">HH</text>)~"))).x0 == Approx(100 - 22 + 4));
  CHECK(ink(parse_text_svg(page_svg(R"~(<text x="100" y="50" font-size="32" style="text-anchor:end">HH</text>)~"))).x1 == Approx(100 - 4));
  // font-size in other units and em; a transform on the text
  CHECK(ink(parse_text_svg(page_svg(R"~(<text x="0" y="50" font-size="24pt">H</text>)~"))).y0 == Approx(50 - 21.0 * 32 / 32));
  Box t = ink(parse_text_svg(page_svg(R"~(<text x="10" y="50" font-size="32" transform="translate(5 -10) scale(0.5)">H</text>)~")));
  CHECK(t.x0 == Approx(5 + 0.5 * 14));
  CHECK(t.y1 == Approx(-10 + 0.5 * 50));
}

TEST_CASE("text: tspans with their own positions, per-character dx, tref and whitespace", "[svg][text]") {
  Drawing d = parse_text_svg(page_svg(R"~(<text x="10" y="20" font-size="32">H<tspan x="100" y="80" fill="#ff0000">H</tspan></text>)~"));
  REQUIRE(d.layers.size() == 2);  // black and red pens
  CHECK(ink(d).x1 == Approx(118));
  CHECK(ink(d).y1 == Approx(80));
  // dx shifts characters one by one; a run of spaces counts once
  const Box a = ink(parse_text_svg(page_svg(R"~(<text x="0" y="50" font-size="32" dx="0 10">H   H</text>)~")));
  CHECK(a.x1 == Approx(22 + 16 + 10 + 18));  // H, one space, H moved by 10
  const Box p = ink(parse_text_svg(page_svg(R"~(<text xml:space="preserve" x="0" y="50" font-size="32">H   H</text>)~")));
  CHECK(p.x1 == Approx(22 + 3 * 16 + 18));
  Drawing r = parse_text_svg(page_svg(R"~(<defs><text id="src">H</text></defs><text x="10" y="50" font-size="32"><tref xlink:href="#src"/></text>)~"));
  CHECK(ink(r).x0 == Approx(14));
  // characters the fonts lack are left out and counted, the others still drawn
  SvgReadReport report;
  CHECK(parse_svg(page_svg("<text x=\"10\" y=\"50\">\xce\xa9\xce\xa9 H</text>"), "t.svg", {}, &report).layers.at(0).lines.size() == 3);
  CHECK(report.missing_glyphs == 2);
  // invisible text draws nothing
  CHECK(parse_text_svg(page_svg(R"~(<text x="10" y="50" fill="none">H</text><line x1="0" y1="0" x2="1" y2="0" stroke="black"/>)~"))
            .layers.at(0).lines.size() == 1);
}

TEST_CASE("text on a path follows it, and flowed text wraps in its region", "[svg][text]") {
  Drawing d = parse_text_svg(page_svg(R"~(<defs><path id="up" d="M 50 90 L 50 10"/></defs>
      <text font-size="32"><textPath xlink:href="#up" startOffset="10">H</textPath></text>)~"));
  // running up the page, the glyph is turned a quarter: its 21-unit height lies along -x
  const Box b = ink(d);
  CHECK(b.x1 == Approx(50));
  CHECK(b.x0 == Approx(29));
  CHECK(b.y1 == Approx(90 - 10 - 4));
  CHECK(b.y0 == Approx(90 - 10 - 18));
  Drawing f = parse_text_svg(page_svg(R"~(<flowRoot font-size="32"><flowRegion><rect x="10" y="10" width="60" height="80"/></flowRegion>
      <flowPara>HH HH</flowPara></flowRoot>)~"));
  const Box fb = ink(f);
  CHECK(fb.x1 < 70);  // the second word wrapped onto a second line
  CHECK(fb.y1 == Approx(10 + 32 + 40));
}

TEST_CASE("filled shapes become areas with their fill rule, on the fill colour's pen", "[svg][fill]") {
  Drawing d = parse_text_svg(page_svg(R"~(
      <path d="M0 0 H10 V10 H0 Z M3 3 V7 H7 V3 Z" fill="#0000ff" fill-rule="evenodd"/>
      <rect x="20" y="0" width="10" height="10" fill="red" stroke="black"/>
      <rect x="40" y="0" width="10" height="10" fill="url(#gradient)"/>
      <polyline points="60,0 70,0 70,10" fill="green"/>
      <line x1="80" y1="0" x2="90" y2="0" stroke="black" fill="red"/>
      <rect x="100" y="0" width="10" height="10" fill="none" stroke="none"/>
      <rect x="120" y="0" width="10" height="10" fill="black" fill-opacity="0"/>)~"));
  auto layer = [&](Color c) -> const Layer& {
    for (const auto& l : d.layers)
      if (l.pen.color == c) return l;
    FAIL("no layer of colour " << c.hex());
    return d.layers[0];
  };
  const Layer& blue = layer({0, 0, 255});
  REQUIRE(blue.areas.size() == 1);
  CHECK(blue.areas[0].rule == FillRule::evenodd);
  CHECK(blue.areas[0].rings.size() == 2);
  CHECK(blue.lines.size() == 2);  // the outline of an unstroked fill, drawn with its pen
  const Layer& red = layer({255, 0, 0});
  CHECK(red.areas.size() == 1);  // the fill on the red pen ...
  CHECK(red.lines.empty());
  const Layer& black = layer(colors::black);
  CHECK(black.areas.empty());     // ... its stroke, the line and the gradient's outline on black
  CHECK(black.lines.size() == 3);
  const Layer& green = layer({0, 128, 0});
  REQUIRE(green.areas.size() == 1);  // a filled polyline closes for its fill
  CHECK(green.areas[0].rings[0].pts.front() == green.areas[0].rings[0].pts.back());
  size_t all = 0;
  for (const auto& l : d.layers) all += l.areas.size();
  CHECK(all == 3);  // nothing for the unpainted and the transparent rects
}

TEST_CASE("a circle filled and stroked in two colours goes to two pens", "[svg][fill]") {
  Drawing d = parse_text_svg(page_svg(R"~(<circle cx="50" cy="50" r="10" fill="red" stroke="black"/>
      <circle cx="80" cy="50" r="10" fill="black" stroke="black"/>)~"));
  REQUIRE(d.layers.size() == 2);
  size_t filled = 0, outlines = 0;
  for (const auto& l : d.layers)
    for (const auto& c : l.circles) (c.filled ? filled : outlines)++;
  CHECK(filled == 2);
  CHECK(outlines == 1);
}

TEST_CASE("UTF-8 decoding keeps code points and marks bad bytes", "[svg][text]") {
  CHECK(svgtext::decode_utf8("a\xc3\xa9\xe2\x82\xac") == std::u32string{U'a', U'\u00e9', U'\u20ac'});
  CHECK(svgtext::decode_utf8("\xff") == std::u32string{0xFFFD});
  CHECK(svgtext::decode_utf8("\xc3") == std::u32string{0xFFFD});
}
