// Any SVG onto any plotter, through the real executable: where a fitted, turned and
// centred drawing lands on the device; Inkscape's example drawings; layers and pens; the
// default page of a method on a device; bad layout options.
#include <catch2/catch.hpp>

#include "test_util.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/job/hpgl_reader.hpp"
#include "geometry/drawing.hpp"

namespace fs = std::filesystem;
using stipplot::Vec2;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

double segment_distance(Vec2 p, Vec2 a, Vec2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
  const double t = l2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / l2, 0.0, 1.0) : 0;
  return std::hypot(a.x + t * dx - p.x, a.y + t * dy - p.y);
}

double distance_to_ring(Vec2 p, const std::vector<Vec2>& ring) {
  double best = 1e9;
  for (size_t k = 1; k < ring.size(); ++k) best = std::min(best, segment_distance(p, ring[k - 1], ring[k]));
  return best;
}

// Pen-down vertices of an HPGL job, in mm on the machine (40 units a mm).
std::vector<Vec2> hpgl_down_points(const std::string& text) {
  std::vector<Vec2> out;
  for (const auto& l : stipplot::io::parse_hpgl_job(text).lines) {
    if (l.text.rfind("PD", 0) != 0) continue;  // the writer's PD hold absolute points
    const auto n = stipplot::io::hpgl_numbers(std::string_view(l.text).substr(2));
    for (size_t k = 0; k + 1 < n.size(); k += 2) out.push_back({n[k] / 40, n[k + 1] / 40});
  }
  return out;
}

// Pen-down vertices of a grbl-servo job: G1 moves, in machine mm.
std::vector<Vec2> gcode_down_points(const std::string& text) {
  std::vector<Vec2> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("G1 X", 0) != 0) continue;
    double x = 0, y = 0;
    if (std::sscanf(line.c_str(), "G1 X%lf Y%lf", &x, &y) == 2) out.push_back({x, y});
  }
  return out;
}

// An A4 portrait drawing in px (96/in, as Inkscape writes it) holding one rectangle, ink
// 100 x 200 mm from (30, 40) mm.
const char* kPortraitRect =
    R"(<svg xmlns="http://www.w3.org/2000/svg" width="210mm" height="297mm" viewBox="0 0 793.7007874 1122.519685">)"
    R"(<rect x="113.3858268" y="151.1811024" width="377.9527559" height="755.9055118" fill="none" stroke="black"/></svg>)";

}  // namespace

TEST_CASE("a drawing fitted, turned and centred lands within 0.05 mm of where it should", "[cli][layout]") {
  test::TempDir t;
  std::ofstream(t.file("rect.svg")) << kPortraitRect;
  // The HP 7475A's A4 sheet lies landscape (297 x 210); its pen reaches 10.5..286.5 x 8.485..201.51 mm
  // of it. The ink, portrait, is turned (x, y) -> (y, 210 - x): 200 x 100 mm from (40, 80); fitted
  // into the sheet less 15 mm margins, 267 x 180 mm from (15, 15): k = 1.335, centred vertically.
  auto r = test::run_cli("export " + t.file("rect.svg") + " --profile hp7475a-a4 --fit --margin 15mm -o " + t.file("r.hpgl"));
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("rotated 90°") != std::string::npos);
  const double k = 1.335, ox = 15, oy = 15 + (180 - 100 * k) / 2;
  auto sheet = [&](double x, double y) { return Vec2{ox + k * (y - 40), oy + k * (210 - x - 80)}; };
  // sheet (top-left, y down) -> machine (lower-left hard-clip corner, y up)
  auto machine = [](Vec2 s) { return Vec2{s.x - 10.5, 210 - s.y - 8.49}; };
  std::vector<Vec2> want;
  for (Vec2 c : {Vec2{30, 40}, Vec2{130, 40}, Vec2{130, 240}, Vec2{30, 240}, Vec2{30, 40}}) want.push_back(machine(sheet(c.x, c.y)));
  const auto drawn = hpgl_down_points(slurp(t.file("r.hpgl")));
  REQUIRE(drawn.size() >= 4);
  for (const Vec2& p : drawn) CHECK(distance_to_ring(p, want) <= 0.05);
  for (const Vec2& c : want) {
    double nearest = 1e9;
    for (const Vec2& p : drawn) nearest = std::min(nearest, std::hypot(p.x - c.x, p.y - c.y));
    CHECK(nearest <= 0.05);  // every corner is drawn
  }

  // On grbl-servo's A3 sheet (420 x 297, machine zero at its lower left), turned by hand a quarter
  // clockwise ((x, y) -> (297 - y, x) on the A4 page turned) and centred without scaling.
  r = test::run_cli("export " + t.file("rect.svg") + " --profile grbl-servo --rotate 90 --center -o " + t.file("r.gcode"));
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  // ink after the turn: 200 x 100 from (57, 30); centred in 400 x 277 from (10, 10): at (110, 98.5)
  auto a3 = [](double x, double y) { return Vec2{110 + (297 - y - 57), 98.5 + (x - 30)}; };
  std::vector<Vec2> want_g;
  for (Vec2 c : {Vec2{30, 40}, Vec2{130, 40}, Vec2{130, 240}, Vec2{30, 240}, Vec2{30, 40}}) {
    const Vec2 s = a3(c.x, c.y);
    want_g.push_back({s.x, 297 - s.y});
  }
  const auto drawn_g = gcode_down_points(slurp(t.file("r.gcode")));
  REQUIRE(drawn_g.size() >= 4);
  for (const Vec2& p : drawn_g) CHECK(distance_to_ring(p, want_g) <= 0.05);
}

TEST_CASE("Inkscape's example drawings plot on grbl-servo and, fitted, on the HP 7475A", "[cli][layout][inkscape]") {
  const fs::path dir = "/usr/share/inkscape/examples";
  if (!fs::is_directory(dir)) FAIL("Inkscape's examples are missing: run scripts/setup.sh (Debian's inkscape package)");
  // Raster images and filters only: nothing a pen can draw.
  const std::vector<std::string> no_drawable_content = {"replace-hue.svg"};
  test::TempDir t;
  size_t plotted = 0, files = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".svg") continue;
    ++files;
    const std::string name = e.path().filename().string();
    const bool expect_ok =
        std::find(no_drawable_content.begin(), no_drawable_content.end(), name) == no_drawable_content.end();
    bool ok = true;
    for (const std::string& how : {std::string("--profile grbl-servo -o ") + t.file("x.gcode"),
                                   std::string("--profile hp7475a-a4 --fit -o ") + t.file("x.hpgl")}) {
      auto r = test::run_cli("export " + e.path().string() + " " + how + " --optimize-seconds 0 --json");
      INFO(name << " " << how << ": " << r.err);
      if (!expect_ok) {
        CHECK(r.exit_code != 0);
        CHECK(r.err.find("nothing to plot") != std::string::npos);
        ok = false;
        continue;
      }
      CHECK(r.exit_code == 0);
      if (r.exit_code != 0) {
        ok = false;
        continue;
      }
      const auto j = nlohmann::json::parse(r.out);
      CHECK(j["plan"]["total"]["pen_down_mm"].get<double>() > 10);
    }
    plotted += ok;
  }
  CHECK(files == 23);
  CHECK(plotted == 22);
}

TEST_CASE("the text-only examples plot their text", "[cli][layout][inkscape]") {
  const fs::path dir = "/usr/share/inkscape/examples";
  if (!fs::is_directory(dir)) FAIL("Inkscape's examples are missing: run scripts/setup.sh (Debian's inkscape package)");
  test::TempDir t;
  // each holds only text (and, data_uri, a raster image): a few hundred glyph strokes
  for (const char* name : {"data_uri.svg", "flowsample.svg", "svgfont.svg", "tref.svg", "i18n.svg"}) {
    auto r = test::run_cli("export " + (dir / name).string() + " --profile hp7475a-a4 --fit -o " + t.file("t.hpgl") +
                           " --optimize-seconds 0 --json");
    INFO(name << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(nlohmann::json::parse(r.out)["plan"]["total"]["strokes"].get<int>() > 100);
  }
}

TEST_CASE("layer and pen options choose what is drawn with which pen", "[cli][layout][pens]") {
  test::TempDir t;
  const std::string foreign = std::string(STIPPLOT_SOURCE_DIR) + "/examples/foreign.svg";
  auto r = test::run_cli("export " + foreign + " --profile hp7475a-a4 --layer 2 -o " + t.file("red.hpgl"));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  std::string text = slurp(t.file("red.hpgl"));
  CHECK(text.find("SP2;") != std::string::npos);  // the red layer keeps its pen
  CHECK(text.find("SP1;") == std::string::npos);
  // both layers on pen 3: one pen, taken up once
  r = test::run_cli("export " + foreign + " --profile hp7475a-a4 --pen-map 1=3,red=3 -o " + t.file("one.hpgl") + " --json");
  REQUIRE(r.exit_code == 0);
  text = slurp(t.file("one.hpgl"));
  CHECK(text.find("SP3;") != std::string::npos);
  CHECK(text.find("SP1;") == std::string::npos);
  CHECK(nlohmann::json::parse(r.out)["plan"]["layers"].size() == 1);
  // pens beyond the carousel: a reload pause naming them
  r = test::run_cli("export " + foreign + " --profile hp7475a-a4 --pen-map black=7,red=8 -o " + t.file("reload.hpgl"));
  REQUIRE(r.exit_code == 0);
  text = slurp(t.file("reload.hpgl"));
  CHECK(text.find("SP0;CO\"stipplot pause: load pen 7 black #000000 in slot 1, pen 8 red #dd0000 in slot 2\";SP1;") !=
        std::string::npos);
  // bad items are named
  r = test::run_cli("export " + foreign + " --layer 9 -o " + t.file("x.gcode"));
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("--layer 9") != std::string::npos);
  CHECK_FALSE(fs::exists(t.file("x.gcode")));
  r = test::run_cli("export " + foreign + " --pen-map purple=2 -o " + t.file("x.gcode"));
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("purple") != std::string::npos);
}

TEST_CASE("a page option names the paper on the machine, lying as the machine takes its sheet", "[cli][layout]") {
  test::TempDir t;
  const std::string foreign = std::string(STIPPLOT_SOURCE_DIR) + "/examples/foreign.svg";
  auto sheet_of = [&](const std::string& args) {
    auto r = test::run_cli("export " + foreign + " " + args + " -o " + t.file("x.hpgl") + " --json");
    INFO(args << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    return nlohmann::json::parse(r.out)["layout"]["sheet_mm"];
  };
  CHECK(sheet_of("--profile hp7475a-a4") == nlohmann::json::array({297.0, 210.0}));
  CHECK(sheet_of("--profile hp7475a-a4 --page A4") == nlohmann::json::array({297.0, 210.0}));  // named: lies landscape
  CHECK(sheet_of("--profile hp7475a-a3 --page A4 --fit") == nlohmann::json::array({297.0, 210.0}));
  CHECK(sheet_of("--profile hp7475a-a3 --page 250x280mm --fit") == nlohmann::json::array({250.0, 280.0}));  // WxH as given
}

TEST_CASE("bad layout options are one error line, and no file", "[cli][layout]") {
  test::TempDir t;
  const std::string foreign = std::string(STIPPLOT_SOURCE_DIR) + "/examples/foreign.svg";
  for (const char* bad : {"--fit --scale 2", "--align middle", "--scale -1", "--crop 1,2,3", "--margin 10furlong",
                          "--align top --center", "--rotate x", "--crop 0,0,0,10"}) {
    auto r = test::run_cli("export " + foreign + " " + bad + " -o " + t.file("x.gcode"));
    INFO(bad << ": " << r.err);
    CHECK(r.exit_code == 1);
    CHECK(r.err.rfind("stipplot: error: ", 0) == 0);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(t.file("x.gcode")));
  }
  // a margin that leaves nothing of the sheet
  auto r = test::run_cli("export " + foreign + " --fit --margin 20cm -o " + t.file("x.gcode"));
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("leaves no room") != std::string::npos);
}

TEST_CASE("a method's plot for the HP 7475A just works: its sheet, turned, inside the reach", "[cli][layout]") {
  test::TempDir t;
  const std::string horse = std::string(STIPPLOT_SOURCE_DIR) + "/examples/horse.png";
  auto r = test::run_cli("stipple " + horse + " -a 4px -b 20px -o " + t.file("p.hpgl") + " --profile hp7475a-a4 --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["layout"]["sheet_mm"] == nlohmann::json::array({297.0, 210.0}));
  CHECK(j["layout"]["margin_mm"].get<double>() == Approx(10.5));  // the 10 mm default is outside the reach
  CHECK(j["layout"]["clipped_dropped"] == 0);
}
