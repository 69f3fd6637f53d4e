// The CLI end to end: every variant runs, --json is one line, bad input is one line and
// a non-zero exit with no output file left behind.
#include <catch2/catch.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <thread>
#include <nlohmann/json.hpp>

#include "test_util.hpp"

namespace {
}  // namespace

TEST_CASE("stipple runs every method and writes SVG + preview", "[cli]") {
  test::TempDir t;
  for (const char* m : {"random", "gray", "negative", "binary", "color", "cmyk"}) {
    auto r = test::run_cli("stipple " + test::example("horse.png") + " -o " + t.file("o.svg") + " --preview " +
                           t.file("p.png") + " --method " + m + " -a 2px -b 8px --json");
    INFO(m << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    REQUIRE(test::count_lines(r.out) == 1);
    auto j = nlohmann::json::parse(r.out);
    CHECK(j["method"] == (std::string(m) == "grey" ? "gray" : m));
    CHECK(j["primitives"].get<size_t>() > 100);
    CHECK(std::filesystem::file_size(t.file("o.svg")) > 1000);
    CHECK(std::filesystem::file_size(t.file("p.png")) > 1000);
  }
}

TEST_CASE("every command has --help", "[cli]") {
  for (const char* c : {"stipple", "eval"}) {
    auto r = test::run_cli(std::string(c) + " --help");
    CHECK(r.exit_code == 0);
    CHECK(r.out.find("Example") != std::string::npos);
  }
  auto r = test::run_cli("--help");
  CHECK(r.exit_code == 0);
  CHECK(r.out.find("stipple") != std::string::npos);
}

TEST_CASE("same seed, same file, bit for bit", "[cli]") {
  test::TempDir t;
  std::string base = "stipple " + test::example("coffee.png") + " --method binary --seed 9 -q -o ";
  REQUIRE(test::run_cli(base + t.file("a.svg")).exit_code == 0);
  REQUIRE(test::run_cli(base + t.file("b.svg")).exit_code == 0);
  CHECK(test::read_file(t.file("a.svg")) == test::read_file(t.file("b.svg")));
}

TEST_CASE("stipple with 1 and 2 threads (--threads) writes the same drawing bit for bit, a negative or huge count is refused", "[cli][threads]") {
  test::TempDir t;
  std::string base = "stipple " + test::example("coffee.png") + " -q -o ";
  REQUIRE(test::run_cli(base + t.file("one.svg") + " --threads 1").exit_code == 0);
  REQUIRE(test::run_cli(base + t.file("two.svg") + " --threads 2").exit_code == 0);
  CHECK(test::read_file(t.file("one.svg")) == test::read_file(t.file("two.svg")));
  auto r = test::run_cli(base + t.file("bad.svg") + " --threads -1");
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("--threads") != std::string::npos);
  CHECK(!std::filesystem::exists(t.file("bad.svg")));
  r = test::run_cli(base + t.file("bad.svg") + " --threads 100000");  // more than any machine: refused, not a crash
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("--threads") != std::string::npos);
}

TEST_CASE("more threads than the machine has cores: the same drawing and not a word on stderr", "[cli][threads]") {
  // OpenCV's TBB pool refuses more workers than cores and said so on stderr (--threads 3
  // on two cores); its count is capped at the cores, the OpenMP parts take what is asked.
  test::TempDir t;
  const std::string base = "stipple " + test::example("coffee.png") + " -q -o ";
  const unsigned more = 2 * std::max(1u, std::thread::hardware_concurrency()) + 1;
  REQUIRE(test::run_cli(base + t.file("one.svg") + " --threads 1").exit_code == 0);
  const auto r = test::run_cli(base + t.file("many.svg") + " --threads " + std::to_string(more));
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK(test::read_file(t.file("one.svg")) == test::read_file(t.file("many.svg")));
}

TEST_CASE("sketch and tree and pointillism with 1 and 2 threads write the same drawing bit for bit", "[cli][threads]") {
  // sketch links each pen's strokes on a thread of its own; tree and pointillism time
  // their long strokes side by side (drivers/motion/time_model.cpp).
  test::TempDir t;
  for (const std::string method : {"sketch", "tree", "pointillism"}) {
    INFO(method);
    const std::string base = method + " " + test::example("coffee.png") + " -q -o ";
    REQUIRE(test::run_cli(base + t.file(method + "1.svg") + " --threads 1").exit_code == 0);
    REQUIRE(test::run_cli(base + t.file(method + "2.svg") + " --threads 2").exit_code == 0);
    CHECK(test::read_file(t.file(method + "1.svg")) == test::read_file(t.file(method + "2.svg")));
  }
}

TEST_CASE("export with 1 and 2 threads writes the same G-code: a 5 MB SVG of 300,000 dots, tokenised apart, planned in halves", "[cli][threads]") {
  test::TempDir t;
  {
    std::ofstream svg(t.file("dots.svg"));
    svg << R"(<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="200mm" viewBox="0 0 200 200"><g fill="#000">)" << "\n";
    uint64_t x = 88172645463325252ull;  // xorshift: the same file each run
    auto next = [&] { return x ^= x << 13, x ^= x >> 7, x ^= x << 17; };
    for (int i = 0; i < 300'000; ++i)
      svg << "<circle cx=\"" << (next() % 200000) / 1000.0 << "\" cy=\"" << (next() % 200000) / 1000.0 << "\" r=\"0.15\"/>\n";
    svg << "</g></svg>\n";
  }
  REQUIRE(std::filesystem::file_size(t.file("dots.svg")) > (size_t{4} << 20));  // over the size read on two threads
  const std::string base = "export " + t.file("dots.svg") + " -q -o ";
  REQUIRE(test::run_cli(base + t.file("one.gcode") + " --threads 1").exit_code == 0);
  REQUIRE(test::run_cli(base + t.file("two.gcode") + " --threads 2").exit_code == 0);
  const std::string one = test::read_file(t.file("one.gcode"));
  CHECK(one.size() > 300'000 * 20);
  CHECK(one == test::read_file(t.file("two.gcode")));
  CHECK(test::run_cli(base + t.file("bad.gcode") + " --threads -1").exit_code == 1);
}

TEST_CASE("bad input: one error line, non-zero exit, no output file", "[cli][bad-input]") {
  test::TempDir t;
  { std::ofstream(t.file("empty.png")); }
  { std::ofstream(t.file("junk.jpg")) << "plain text, not a JPEG"; }
  std::string png = test::read_file(test::example("horse.png"));
  { std::ofstream(t.file("trunc.png"), std::ios::binary) << png.substr(0, png.size() / 3); }
  const std::string out = t.file("out.svg"), prev = t.file("out.png");
  struct Case {
    std::string args, expect;
  };
  std::vector<Case> cases = {
      {t.file("missing.png"), "no such file"},
      {t.file("empty.png"), "empty"},
      {t.file("junk.jpg"), "not a readable image"},
      {t.file("trunc.png"), "truncated"},
      {test::example("horse.png") + " --max-pixels 100", "--max-pixels"},
      {test::example("horse.png") + " -a nan", "-a"},
      {test::example("horse.png") + " -b -3", "-b"},
      {test::example("horse.png") + " --a-w inf", "--a-w"},
      {test::example("horse.png") + " --method pointy", "pointy"},
      {test::example("horse.png") + " --page B9", "--page"},
      {test::example("horse.png") + " --margin 200", "margin"},
      {test::example("horse.png") + " --pen-width 0", "--pen-width"},
      {test::example("horse.png") + " --dot-size -1px", "--dot-size"},
  };
  for (const auto& c : cases) {
    auto r = test::run_cli("stipple " + c.args + " -o " + out + " --preview " + prev);
    INFO(c.args << " -> " << r.err);
    CHECK(r.exit_code != 0);
    CHECK(r.exit_code < 64);  // a user error, not a crash or internal error
    CHECK(test::count_lines(r.err) == 1);
    CHECK(r.err.find(c.expect) != std::string::npos);
    CHECK(!std::filesystem::exists(out));
    CHECK(!std::filesystem::exists(prev));
  }
  auto r = test::run_cli("stipple " + test::example("horse.png") + " -o /no/such/dir/x.svg");
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("does not exist") != std::string::npos);
  r = test::run_cli("stipple " + test::example("horse.png") + " -o " + t.file("x.pdf"));
  CHECK(r.exit_code != 0);
  CHECK(r.err.find(".pdf") != std::string::npos);
}

TEST_CASE("eval prints blurred SSIM and edge spill", "[cli][eval]") {
  test::TempDir t;
  REQUIRE(test::run_cli("stipple " + test::example("horse.png") + " -q -o " + t.file("h.svg") + " --preview " +
                        t.file("h.png") + " --law linear -a 2px -b 8px --landscape")
              .exit_code == 0);
  auto r = test::run_cli("eval " + test::example("horse.png") + " " + t.file("h.png") + " --landscape --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  auto j = nlohmann::json::parse(r.out);
  CHECK(j["ssim_blurred"].get<double>() > 0.3);
  CHECK(j["edge_spill"].get<double>() >= 0);
  CHECK(j["dots"].get<size_t>() > 100);
  // without the same page options the shape doesn't match: a clear error
  r = test::run_cli("eval " + test::example("horse.png") + " " + t.file("h.png"));
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("--page") != std::string::npos);
}

TEST_CASE("export --preview is the pen-true render of the plan, not the drawing's shapes", "[cli][export][preview]") {
  test::TempDir t;
  // A filled red circle: the drawing is a red disc, but with --fill none the pen only
  // draws its outline, and the preview must show what the pen draws.
  std::ofstream(t.file("c.svg")) << R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">)"
                                 << R"(<circle cx="50" cy="50" r="20" fill="#ff0000" stroke="#ff0000"/></svg>)";
  auto centre_and_rim = [&](const std::string& fill) {
    const auto r = test::run_cli("export " + t.file("c.svg") + " -o " + t.file("c-" + fill + ".gcode") + " --preview " +
                                 t.file("c-" + fill + ".png") + " --fill " + fill);
    REQUIRE(r.exit_code == 0);
    const stipplot::Image im = stipplot::load_image(t.file("c-" + fill + ".png"));
    // The drawing sits at the sheet's top-left corner (no --fit): 150 dpi, mm -> px.
    const double px = 150 / 25.4;
    auto green = [&](double x_mm, double y_mm) {  // the darkest in a 5 x 5 px window (the pen is 1.8 px)
      int g = 255;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx)
          g = std::min(g, static_cast<int>(im.channel(static_cast<int>(x_mm * px) + dx, static_cast<int>(y_mm * px) + dy, 1)));
      return g;
    };
    return std::pair<int, int>{green(50, 50), green(70, 50)};
  };
  const auto [outline_centre, outline_rim] = centre_and_rim("none");
  CHECK(outline_centre > 240);  // paper: nothing drawn inside the outline
  CHECK(outline_rim < 120);     // red ink on the rim
  const auto [filled_centre, filled_rim] = centre_and_rim("spiral");
  CHECK(filled_centre < 120);   // the spiral fills it
  CHECK(filled_rim < 120);
}
