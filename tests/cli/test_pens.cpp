// Real pens in every colour method: each pen one layer, light before dark, every shipped
// palette with every colour method, --max-pens, reload pauses past the carousel.
#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "geometry/drawing.hpp"
#include "methods/palette.hpp"
#include "test_util.hpp"

using namespace stipplot;

namespace {
std::string shared_image(const std::string& name) { return std::string(STIPPLOT_SHARED_DIR) + "/images/" + name; }
const std::string kFineliners = test::example("pens/fineliner12.toml");

const std::vector<std::string> kColourMethods = {"sketch", "pointillism", "stipple -m color", "stipple -m cmyk"};

// The layers of a --json result: each pen once, light before dark, every pen from `toml`.
void check_pens_once_light_to_dark(const nlohmann::json& j, const std::string& toml) {
  std::set<std::string> names;
  double prev = 2;
  for (const auto& l : j["layers"]) {
    const std::string name = l["pen"].get<std::string>(), hex = l["color"].get<std::string>();
    INFO("layer " << name << " " << hex);
    CHECK(names.insert(name).second);
    CHECK(toml.find("\"" + name + "\"") != std::string::npos);
    CHECK(toml.find("\"" + hex + "\"") != std::string::npos);
    const double lum = relative_luminance(Color::parse(hex));
    CHECK(lum <= prev);
    prev = lum;
  }
}

size_t pen_count(const std::string& toml) {
  size_t n = 0;
  for (size_t at = toml.find("[[pen]]"); at != std::string::npos; at = toml.find("[[pen]]", at + 1)) ++n;
  return n;
}
}  // namespace

TEST_CASE("every example palette with every colour method draws each pen once, light to dark, or errors in one line", "[cli][palette]") {
  test::TempDir t;
  size_t palettes = 0;
  for (const auto& e : std::filesystem::directory_iterator(test::example("pens"))) {
    const std::string pal = e.path().string();
    const std::string toml = test::read_file(pal);
    ++palettes;
    for (const std::string& method : kColourMethods) {
      auto r = test::run_cli(method + " " + test::example("horse.png") + " --pens " + pal + " -o " + t.file("o.svg") + " --json");
      INFO(method << " --pens " << pal << ": " << r.err);
      if (method == "stipple -m cmyk" && e.path().filename() == "black.toml") {
        // Documented: cmyk needs a pen near each process ink; one black pen has none.
        CHECK(r.exit_code != 0);
        CHECK(r.err.find("needs a pen near cyan") != std::string::npos);
        CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
        CHECK_FALSE(std::filesystem::exists(t.file("o.svg")));
        continue;
      }
      REQUIRE(r.exit_code == 0);
      auto j = nlohmann::json::parse(r.out);
      // Marks: a sketch's strokes before they are linked into scribbles.
      CHECK((j.contains("linked") ? j["linked"]["strokes"] : j["primitives"]).get<size_t>() > 100);
      REQUIRE(j["layers"].size() >= 1);
      CHECK(j["layers"].size() <= pen_count(toml));
      check_pens_once_light_to_dark(j, toml);
      std::filesystem::remove(t.file("o.svg"));
    }
  }
  CHECK(palettes == 4);
}

TEST_CASE("pointillism and sketch with fineliner12: one layer a pen, light before dark, each pen taken up once in the plan", "[cli][palette]") {
  test::TempDir t;
  const std::string toml = test::read_file(kFineliners);
  for (const std::string& method : {std::string("pointillism"), std::string("sketch")}) {
    auto r = test::run_cli(method + " " + shared_image("starry_night.jpg") + " --pens " + kFineliners + " -o " +
                           t.file("o.svg") + " --json");
    INFO(method << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    auto j = nlohmann::json::parse(r.out);
    CHECK(j["layers"].size() >= 6);  // a colourful painting uses most of the twelve
    check_pens_once_light_to_dark(j, toml);
    // The planner takes each pen up once: as many planned layers as drawing layers.
    CHECK(j["plan"]["layers"].size() == j["layers"].size());
  }
}

TEST_CASE("max pens: --max-pens N draws with N pens that beat the palette's first N", "[cli][palette][max-pens]") {
  test::TempDir t;
  // The palette's first four pens (black, grey, brown, red), the fixed other choice.
  const std::string toml = test::read_file(kFineliners);
  size_t fifth = toml.find("[[pen]]");
  for (int i = 0; i < 4; ++i) fifth = toml.find("[[pen]]", fifth + 1);
  {
    std::ofstream f(t.file("first4.toml"));
    f << toml.substr(0, fifth);
  }
  struct Case {
    std::string method, measure, key;
  };
  for (const Case& c : {Case{"pointillism", "--fidelity", "mean_de00"}, Case{"sketch", "--measure", "delta_e00"}}) {
    const std::string base = c.method + " " + shared_image("starry_night.jpg") + " " + c.measure + " --time 8h -o " + t.file("o.svg") + " --json ";
    auto chosen = test::run_cli(base + "--pens " + kFineliners + " --max-pens 4");
    auto first = test::run_cli(base + "--pens " + t.file("first4.toml"));
    INFO(c.method << ": " << chosen.err << first.err);
    REQUIRE(chosen.exit_code == 0);
    REQUIRE(first.exit_code == 0);
    const auto jc = nlohmann::json::parse(chosen.out), jf = nlohmann::json::parse(first.out);
    REQUIRE(jc["max_pens"]["pens"].size() == 4);
    std::set<std::string> picked;
    for (const auto& p : jc["max_pens"]["pens"]) picked.insert(p.get<std::string>());
    CHECK(picked.size() == 4);
    CHECK(jc["layers"].size() == 4);
    for (const auto& l : jc["layers"]) CHECK(picked.count(l["pen"].get<std::string>()) == 1);
    CHECK(chosen.err.empty());
    CHECK(jc[c.key].get<double>() <= jf[c.key].get<double>());
    CHECK(jc["max_pens"]["evaluations"].get<size_t>() == 4 * 12 - 6);  // greedy: n P - n (n - 1) / 2
  }
  // stipple -m color: the chosen pens, named in the result line.
  auto s = test::run_cli("stipple -m color " + test::example("coffee.png") + " --pens " + kFineliners + " --max-pens 3 -o " + t.file("s.svg"));
  INFO(s.err);
  REQUIRE(s.exit_code == 0);
  CHECK(s.out.find("pens chosen: ") != std::string::npos);
}

TEST_CASE("max pens: --max-pens outside 1 .. the palette, or without one, is a one-line error", "[cli][palette][max-pens]") {
  test::TempDir t;
  for (const std::string& bad : {"--pens " + kFineliners + " --max-pens 13", "--pens " + kFineliners + " --max-pens 0",
                                 "--pens " + kFineliners + " --max-pens -2", std::string("--max-pens 3")}) {
    for (const std::string& method : kColourMethods) {
      auto r = test::run_cli(method + " " + test::example("horse.png") + " " + bad + " -o " + t.file("o.svg"));
      INFO(method << " " << bad << ": " << r.err);
      CHECK(r.exit_code != 0);
      CHECK(r.err.find("--max-pens") != std::string::npos);
      CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
      CHECK_FALSE(std::filesystem::exists(t.file("o.svg")));
    }
  }
}

TEST_CASE("a colour drawing with more pens than the carousel gets reload pauses, one pen change a pen", "[cli][palette][carousel]") {
  test::TempDir t;
  auto r = test::run_cli("pointillism " + shared_image("starry_night.jpg") + " --pens " + kFineliners + " -o " +
                         t.file("o.hpgl") + " --profile hp7475a-a4 --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  const size_t layers = j["layers"].size();
  REQUIRE(layers > 6);  // more pens than the HP 7475A's six slots
  const std::string hpgl = test::read_file(t.file("o.hpgl"));
  size_t pauses = 0;
  for (size_t at = hpgl.find("CO\"stipplot pause: load pen"); at != std::string::npos; at = hpgl.find("CO\"stipplot pause: load pen", at + 1)) ++pauses;
  CHECK(pauses >= 1);
  CHECK(pauses <= (layers - 1) / 6);  // each reload loads up to six pens: none wasted
  // One SP a pen (and SP0 to stow it at the end and before each reload).
  size_t selects = 0;
  for (size_t at = hpgl.find("SP"); at != std::string::npos; at = hpgl.find("SP", at + 1))
    if (hpgl.compare(at, 3, "SP0") != 0) ++selects;
  CHECK(selects == layers);
  // A one-holder grbl plotter: an M0 pause at each change, each pen taken up once.
  auto g = test::run_cli("sketch " + shared_image("starry_night.jpg") + " --pens " + kFineliners + " -o " + t.file("o.gcode") + " --json");
  INFO(g.err);
  REQUIRE(g.exit_code == 0);
  const size_t glayers = nlohmann::json::parse(g.out)["layers"].size();
  const std::string gcode = test::read_file(t.file("o.gcode"));
  size_t changes = 0;
  for (size_t at = gcode.find("M0 (MSG,Change pen"); at != std::string::npos; at = gcode.find("M0 (MSG,Change pen", at + 1)) ++changes;
  CHECK(glayers > 1);
  CHECK(changes == glayers - 1);
}

TEST_CASE("merge_layers_by_pen: one layer a pen in first-use order within it, light to dark", "[geometry][pens]") {
  Drawing d;
  const Pen red{"red", Color{220, 30, 30}, 0.4}, yellow{"yellow", Color{250, 220, 20}, 0.4}, black{"black", colors::black, 0.4};
  auto layer = [](const Pen& p, double x, int pass) {
    Layer l;
    l.pen = p;
    Circle c{{x, 0}, 1, true, p.color};
    c.pass = pass;
    l.circles.push_back(c);
    return l;
  };
  d.layers = {layer(black, 1, 0), layer(red, 2, 0), layer(yellow, 3, 0), layer(red, 4, 1), layer(black, 5, 1)};
  Layer other_width = layer(red, 6, 0);
  other_width.pen.width_mm = 0.8;  // another pen, though of the same name and colour
  d.layers.push_back(other_width);
  merge_layers_by_pen(d);
  REQUIRE(d.layers.size() == 4);
  CHECK(d.layers[0].pen.name == "yellow");
  CHECK(d.layers[1].pen.name == "red");
  CHECK(d.layers[2].pen.name == "red");  // the 0.8 mm red: equal luminance, stable order
  CHECK(d.layers[2].pen.width_mm == 0.8);
  CHECK(d.layers[3].pen.name == "black");
  REQUIRE(d.layers[1].circles.size() == 2);
  CHECK(d.layers[1].circles[0].c.x == 2);  // merged in layer order, passes kept
  CHECK(d.layers[1].circles[1].c.x == 4);
  CHECK(d.layers[1].circles[1].pass == 1);
  CHECK(d.layers[3].circles[1].c.x == 5);
}

TEST_CASE("cmyk inks go to the palette pens of their hue, where colour alone would pick grey", "[methods][pens]") {
  // Four layers in the process inks (stipple's cmyk_inks colours).
  Drawing d;
  for (const Pen& ink : {Pen{"cyan", {0, 174, 239}, 0.3}, Pen{"magenta", {236, 0, 140}, 0.3},
                         Pen{"yellow", {255, 221, 0}, 0.3}, Pen{"black", colors::black, 0.3}}) {
    Layer l;
    l.pen = ink;
    l.dots.push_back(Dot{{1, 1}, 0.3});
    d.layers.push_back(l);
  }
  auto names = [](const Drawing& m) {
    std::vector<std::string> n;
    for (const auto& l : m.layers) n.push_back(l.pen.name);
    return n;
  };
  const auto fine = load_palette(kFineliners).pens;
  CHECK(names(map_layers_to_pens(d, fine, true, InkMatch::hue)) ==
        std::vector<std::string>{"yellow", "turquoise", "pink", "black"});
  // The RGB primaries' palette: by colour alone cyan's nearest is the grey pen; by hue, cyan.
  const auto rgb = load_palette(test::example("pens/paper_rgb.toml")).pens;
  const auto by_colour = names(map_layers_to_pens(d, rgb, true, InkMatch::colour));
  CHECK(std::count(by_colour.begin(), by_colour.end(), "grey") == 1);
  CHECK(std::count(by_colour.begin(), by_colour.end(), "cyan") == 0);
  CHECK(names(map_layers_to_pens(d, rgb, true, InkMatch::hue)) == std::vector<std::string>{"yellow", "cyan", "magenta", "black"});
  // Every layer keeps its width; two inks on one pen share its layer.
  const Drawing one = map_layers_to_pens(d, {Pen{"blue", Color{31, 78, 156}, 0.5}}, false);
  REQUIRE(one.layers.size() == 1);
  CHECK(one.layers[0].dots.size() == 4);
  CHECK(one.layers[0].pen.width_mm == 0.3);
}

TEST_CASE("choose_pens_greedy adds the best pen each round", "[methods][pens]") {
  // Error: distance of the chosen set's sum to 10, pens worth 1 .. 6: greedy takes 6, then 4.
  const std::vector<double> worth{1, 2, 3, 4, 5, 6};
  size_t calls = 0;
  const auto chosen = choose_pens_greedy(worth.size(), 2, [&](const std::vector<size_t>& set) {
    ++calls;
    CHECK(std::is_sorted(set.begin(), set.end()));
    double sum = 0;
    for (size_t i : set) sum += worth[i];
    return std::abs(10 - sum);
  });
  CHECK(chosen == std::vector<size_t>{3, 5});
  CHECK(calls == greedy_pen_evaluations(6, 2));
  CHECK(calls == 11);
  CHECK(choose_pens_greedy(3, 5, [](const std::vector<size_t>&) { return 0.0; }).size() == 3);
}
