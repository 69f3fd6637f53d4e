// `stipplot export` and the methods' `-o x.gcode / x.hpgl` through the real executable.
#include <catch2/catch.hpp>

#include "test_util.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path scratch() {
  fs::path d = fs::temp_directory_path() / ("stipplot_cli_export_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

const std::string kForeign = std::string(STIPPLOT_SOURCE_DIR) + "/examples/foreign.svg";
}  // namespace

TEST_CASE("export writes a foreign SVG for every shipped profile", "[cli][export]") {
  fs::path dir = scratch();
  int status = 0;
  for (const char* prof : {"grbl-servo", "grbl-z", "grbl-laser", "hp7475a-a4", "hp7475a-a3", "roland-dxy1300"}) {
    INFO("profile " << prof);
    bool hpgl = std::string(prof).rfind("grbl", 0) != 0;
    fs::path out = dir / (std::string(prof) + (hpgl ? ".hpgl" : ".gcode"));
    std::string o = test::run_cli_merged("export " + kForeign + " --profile " + prof + " -o " + out.string() + " --json", status);
    INFO(o);
    REQUIRE(status == 0);
    auto j = nlohmann::json::parse(o);
    CHECK(j["profile"] == prof);
    CHECK(j["plan"]["total"]["strokes"].get<int>() >= 9);
    CHECK(j["plan"]["total"]["seconds"].get<double>() > 0);
    std::string text = slurp(out);
    if (hpgl) {
      CHECK(text.rfind("IN;", 0) == 0);
      CHECK(text.find("SP2;") != std::string::npos);  // the red layer's pen
    } else {
      CHECK(text.find("\nG21\nG90\n") != std::string::npos);
      CHECK(text.find("M0 (MSG,Change pen: pen 2 red") != std::string::npos);
    }
  }
  // the planned order as SVG, with the hidden travel layer
  fs::path svg = dir / "planned.svg";
  test::run_cli_merged("export " + kForeign + " -o " + svg.string() + " --show-travel -q", status);
  CHECK(status == 0);
  CHECK(slurp(svg).find("display:none") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("method commands write G-code and HPGL directly", "[cli][export]") {
  fs::path dir = scratch();
  std::string img = std::string(STIPPLOT_SOURCE_DIR) + "/examples/coffee.png";
  int status = 0;
  fs::path g = dir / "c.gcode";
  // The paper's law: every dot one pen touch (the tone law's larger dots are fills).
  std::string o = test::run_cli_merged("stipple " + img + " -o " + g.string() + " --law linear --optimize-seconds 0.2 --json", status);
  INFO(o);
  REQUIRE(status == 0);
  auto j = nlohmann::json::parse(o);
  CHECK(j["profile"] == "grbl-servo");
  size_t dots = j["primitives"].get<size_t>();
  CHECK(j["plan"]["total"]["touches"].get<size_t>() == dots);
  std::string text = slurp(g);
  size_t downs = 0;
  for (size_t p = text.find("\nM3 S1000\n"); p != std::string::npos; p = text.find("\nM3 S1000\n", p + 1)) ++downs;
  CHECK(downs == dots);  // one pen touch per dot

  fs::path h = dir / "c.hpgl";
  test::run_cli_merged("stipple " + img + " -o " + h.string() + " --profile hp7475a-a3 --landscape --page A3 --margin 20 -q", status);
  CHECK(status == 0);
  CHECK(slurp(h).rfind("IN;", 0) == 0);
  fs::remove_all(dir);
}

TEST_CASE("export refuses mismatched profiles, bad SVG and pages that do not fit, leaving no file", "[cli][export]") {
  fs::path dir = scratch();
  int status = 0;
  fs::path out = dir / "x.hpgl";
  std::string o = test::run_cli_merged("export " + kForeign + " --profile grbl-servo -o " + out.string(), status);
  CHECK(status != 0);
  CHECK(o.find("speaks G-code") != std::string::npos);
  CHECK_FALSE(fs::exists(out));

  fs::path bad = dir / "bad.svg";
  std::ofstream(bad) << "<svg xmlns=\"http://www.w3.org/2000/svg\">\n<path d=\"M 0 0 L 1\"/>\n</svg>\n";
  fs::path g = dir / "x.gcode";
  o = test::run_cli_merged("export " + bad.string() + " -o " + g.string(), status);
  CHECK(status != 0);
  CHECK(o.find("line 2: <path>") != std::string::npos);
  CHECK_FALSE(fs::exists(g));

  // an A4 portrait drawing, kept upright, is taller than the 7475A's A4-landscape area
  fs::path portrait = dir / "portrait.svg";
  std::ofstream(portrait) << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"210mm\" height=\"297mm\" "
                             "viewBox=\"0 0 210 297\"><line x1=\"20\" y1=\"20\" x2=\"20\" y2=\"280\" stroke=\"black\"/></svg>";
  fs::path h = dir / "p.hpgl";
  o = test::run_cli_merged("export " + portrait.string() + " --profile hp7475a-a4 --no-rotate -o " + h.string(), status);
  CHECK(status != 0);
  CHECK(o.find("outside the travel of profile hp7475a-a4") != std::string::npos);
  CHECK(o.find("--fit") != std::string::npos);  // the advice names an option export has
  CHECK_FALSE(fs::exists(h));
  // turned to the sheet's orientation, as the AxiDraw tools do, it fits, and says so
  o = test::run_cli_merged("export " + portrait.string() + " --profile hp7475a-a4 -o " + h.string(), status);
  CHECK(status == 0);
  CHECK(o.find("rotated 90° to the sheet's orientation") != std::string::npos);
  CHECK(fs::exists(h));
  fs::remove_all(dir);
}
