// The streaming SVG reader (the default) against the reader that walks tinyxml2's tree of
// the whole file: the same drawing to the last bit, or the same error, on every SVG the
// project meets (Inkscape's examples, ours, vpype's benchmark file) and on the cases that
// make the stream hold elements back or hand over to the tree (references forward, back
// and into their own target, hidden layers that hold symbols, text split by markup).
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>

#include "svg/svg_reader.hpp"
#include "svg/svg_writer.hpp"
#include "util/error.hpp"

using namespace stipplot;
namespace fs = std::filesystem;

namespace {

// The drawing with every coordinate at full precision, or the error it raised;
// `streamed` says whether the stream read it to the end; `apart`: expat on a thread of its
// own whatever the size and thread count (the stream's two-thread form).
std::string outcome(const std::string& text, bool stream, bool* streamed = nullptr, bool apart = false) {
  SvgReadOptions o;
  o.stream = stream;
  o.tokenize_apart_from_bytes = apart ? 0 : SIZE_MAX;
  try {
    SvgReadReport report;
    const Drawing d = parse_svg(text, "in.svg", o, &report);
    if (streamed) *streamed = report.streamed;
    SvgOptions so;
    so.decimals = 12;
    size_t dots = 0, lines = 0;
    for (const auto& l : d.layers) {
      dots += l.dots.size();
      lines += l.lines.size();
    }
    return svg_string(d, so) + "\nmissing glyphs " + std::to_string(report.missing_glyphs) + ", dots " +
           std::to_string(dots) + ", lines " + std::to_string(lines);
  } catch (const UserError& e) {
    return std::string("error: ") + e.what();
  }
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string page(const std::string& body) {
  return R"(<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" )"
         R"(xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" width="100mm" height="100mm" )"
         R"(viewBox="0 0 100 100">)" +
         body + "</svg>";
}

}  // namespace

TEST_CASE("the streaming SVG reader draws what the tree walk draws, on every SVG file the project knows",
          "[svg][stream]") {
  std::vector<fs::path> files;
  const fs::path inkscape = "/usr/share/inkscape/examples";
  if (!fs::is_directory(inkscape)) FAIL("Inkscape's examples are missing: run scripts/setup.sh (Debian's inkscape package)");
  for (const fs::path& dir : {inkscape, fs::path(STIPPLOT_SOURCE_DIR) / "examples", fs::path(STIPPLOT_SHARED_DIR) / "data"})
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().extension() == ".svg") files.push_back(e.path());
  REQUIRE(files.size() >= 20);
  size_t drawn = 0;
  for (const fs::path& f : files) {
    INFO(f.string());
    const std::string text = slurp(f);
    const std::string streamed = outcome(text, true);
    CHECK(streamed == outcome(text, false));
    CHECK(streamed == outcome(text, true, nullptr, true));
    if (streamed.rfind("error: ", 0) != 0) ++drawn;
  }
  CHECK(drawn >= files.size() - 2);  // a comparison of errors alone would prove little
}

TEST_CASE("the streaming SVG reader matches the tree walk where it must hold elements or hand over", "[svg][stream]") {
  // (what, body, streamed: false where the tree walk must take over)
  const std::vector<std::tuple<std::string, std::string, bool>> cases = {
      {"a symbol in defs, used after",
       R"(<defs><symbol id="s"><circle cx="1" cy="1" r="1" stroke="red" fill="none"/></symbol></defs>)"
       R"~(<use xlink:href="#s" x="10" y="20"/><use href="#s" x="30" y="20" transform="rotate(10)"/>)~", true},
      {"a reference forward (the tree walk takes over)",
       R"(<use xlink:href="#p" x="5"/><g><path id="p" d="M0 0 L10 10" stroke="black"/></g>)", false},
      {"a reference into its own target (a cycle)",
       R"(<g id="g1"><path d="M0 0 L10 10" stroke="black"/><use xlink:href="#g1" x="5"/></g>)", false},
      {"a reference to no element", R"(<use xlink:href="#nothing"/>)", false},
      {"duplicate ids: the first one is the target",
       R"(<path id="d" d="M0 0 L1 1" stroke="black"/><path id="d" d="M0 0 L50 50" stroke="black"/>)"
       R"(<use xlink:href="#d" x="3"/>)", true},
      {"a hidden layer and a '%' layer hold what visible layers use",
       R"(<g inkscape:groupmode="layer" inkscape:label="hidden" style="display:none">)"
       R"(<g><rect id="r" width="4" height="3" stroke="blue" fill="none"/></g></g>)"
       R"(<g inkscape:groupmode="layer" inkscape:label="%notes"><circle id="c" r="2" stroke="green" fill="none"/></g>)"
       R"(<g inkscape:groupmode="layer" inkscape:label="2 ink"><use xlink:href="#r" x="10"/><use xlink:href="#c" x="40" y="40"/></g>)", true},
      {"a referenced group with a layer inside",
       R"~(<g id="grp" transform="translate(5 5)"><g inkscape:groupmode="layer" inkscape:label="inner">)~"
       R"(<line x1="0" y1="0" x2="9" y2="0" stroke="black"/></g></g><use xlink:href="#grp" y="30"/>)", true},
      {"groups nested deep, transforms and styles inherited",
       R"~(<g stroke="red" transform="scale(2)"><g stroke-width="0.5"><g transform="translate(1 2)" fill="none">)~"
       R"(<circle cx="3" cy="3" r="0.1" fill="#000" stroke="none"/><polyline points="0,0 5,5 9,1"/></g></g>)"
       R"(<a><rect x="1" y="1" width="3" height="3"/></a><svg x="20" y="20"><ellipse rx="3" ry="2" stroke="black"/></svg></g>)", true},
      {"text split by markup, whitespace between spans, a tref and a textPath",
       R"(<path id="curve" d="M10 60 Q 50 20 90 60" stroke="none" fill="none"/>)"
       R"(<text id="t" x="10" y="20" font-size="8">Hello<!-- a comment --> <tspan fill="red">big</tspan> )"
       R"(<tspan>world</tspan><![CDATA[ & more]]></text>)"
       R"(<text x="10" y="40" font-size="6"><tref xlink:href="#t"/></text>)"
       R"(<text font-size="5"><textPath xlink:href="#curve">along the curve</textPath></text>)", true},
      {"an error in a shape after a group (no report: nothing returns)",
       R"(<g><path d="M0 0 L1 1" stroke="black"/></g><path d="L 5 5" stroke="black"/>)", false},
      {"an error inside a hidden group is no error", R"(<g style="display:none"><path d="L 5 5"/></g>)", true},
      {"malformed XML", R"(<g><path d="M0 0 L1 1" stroke="black"></g>)", false},
  };
  for (const auto& [what, body, streams] : cases) {
    INFO(what);
    const std::string svg = page(body);
    bool streamed = false;
    const std::string out = outcome(svg, true, &streamed);
    CHECK(out == outcome(svg, false));
    CHECK(streamed == streams);
    bool streamed_apart = false;
    CHECK(out == outcome(svg, true, &streamed_apart, true));
    CHECK(streamed_apart == streams);
  }
  // The root itself hidden, or not an SVG at all.
  CHECK(outcome(R"(<svg xmlns="http://www.w3.org/2000/svg" style="display:none"><path d="M0 0 L1 1" stroke="black"/></svg>)", true) ==
        outcome(R"(<svg xmlns="http://www.w3.org/2000/svg" style="display:none"><path d="M0 0 L1 1" stroke="black"/></svg>)", false));
  CHECK(outcome("<html><body/></html>", true) == outcome("<html><body/></html>", false));
  CHECK(outcome("<html><body/></html>", true).find("not an SVG file") != std::string::npos);
  // An error names the element's line in both.
  const std::string bad = page("\n<g>\n<path d=\"M0 0\" stroke=\"black\"/>\n<circle cx=\"abc\" r=\"1\"/>\n</g>");
  CHECK(outcome(bad, true).find("in.svg line 4: <circle>") != std::string::npos);
  CHECK(outcome(bad, true, nullptr, true).find("in.svg line 4: <circle>") != std::string::npos);
}

TEST_CASE("reading an SVG file streams it: a file on disk reads as its text does", "[svg][stream]") {
  const fs::path f = fs::path(STIPPLOT_SOURCE_DIR) / "examples" / "foreign.svg";
  SvgOptions so;
  so.decimals = 12;
  CHECK(svg_string(read_svg(f.string()), so) == svg_string(parse_svg(slurp(f), f.string()), so));
  CHECK_THROWS_WITH(read_svg("/nonexistent/x.svg"), Catch::Contains("cannot read /nonexistent/x.svg"));
  SvgReadOptions apart;
  apart.tokenize_apart_from_bytes = 0;
  CHECK(svg_string(read_svg(f.string(), apart), so) == svg_string(parse_svg(slurp(f), f.string()), so));
  CHECK_THROWS_WITH(read_svg("/nonexistent/x.svg", apart), Catch::Contains("cannot read /nonexistent/x.svg"));
}

TEST_CASE("expat on a thread of its own: many batches of events, and an error early in a long file", "[svg][stream]") {
  // 60,000 shapes in groups, comments and text between them: a few dozen batches, more
  // than the queue holds, replayed in order.
  std::string body;
  for (int i = 0; i < 60000; ++i) {
    if (i % 1000 == 0) body += "<g stroke=\"#" + std::string(i % 2000 ? "ff0000" : "0000ff") + "\"><!-- group -->";
    body += "<circle cx=\"" + std::to_string(i % 97) + "." + std::to_string(i % 10) + "\" cy=\"" + std::to_string(i % 89) +
            "\" r=\"0.15\" fill=\"#000\" stroke=\"none\"/>\n";
    if (i % 7 == 0) body += "<path d=\"M" + std::to_string(i % 50) + " 1 L 3 4.5\" fill=\"none\"/>";
    if (i % 1000 == 999) body += "</g>";
  }
  const std::string svg = page(body + "<text x=\"5\" y=\"5\" font-size=\"4\">a <tspan>b</tspan> c</text>");
  bool streamed = false;
  const std::string here = outcome(svg, true, &streamed);
  CHECK(streamed);
  CHECK(here.find("dots 60000") != std::string::npos);
  CHECK(outcome(svg, true, nullptr, true) == here);
  // A bad number near the start of a long file: the drawing stops there (the tokenising
  // thread is told to stop while it waits on a full queue), the same error as read here.
  const std::string bad = page("<circle cx=\"x1\" r=\"1\"/>" + body);
  const std::string error = outcome(bad, true, nullptr, true);
  CHECK(error.rfind("error: in.svg line 1: <circle>", 0) == 0);
  CHECK(error == outcome(bad, true));
  // Malformed XML far into the file: the tree reader takes over and says where.
  const std::string broken = page(body + "<g></svg>");
  CHECK(outcome(broken, true, nullptr, true) == outcome(broken, false));
}
