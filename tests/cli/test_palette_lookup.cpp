// --pens NAME finds a shipped palette: in $STIPPLOT_PENS, beside the executable
// (installed: ../share/stipplot/pens) or in the source tree; a path is still a path.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "methods/palette.hpp"
#include "test_util.hpp"
#include "util/error.hpp"

namespace {
// A one-pen palette whose pen has a name no shipped palette has.
void write_lookup_palette(const std::string& path, const std::string& pen) {
  std::ofstream f(path);
  f << "name = \"lookup test\"\n[[pen]]\nname = \"" << pen << "\"\ncolor = \"#202020\"\n";
}

struct ScopedEnv {
  std::string name;
  ScopedEnv(const std::string& n, const std::string& value) : name(n) { ::setenv(n.c_str(), value.c_str(), 1); }
  ~ScopedEnv() { ::unsetenv(name.c_str()); }
};
}  // namespace

TEST_CASE("palettes by name: --pens fineliner12 is a shipped palette, a path stays a path", "[cli][pens]") {
  using stipplot::find_palette;
  const std::string source_pens = std::string(STIPPLOT_SOURCE_DIR) + "/examples/pens";
  // The source tree's palettes by name (the test binary is no installed one).
  CHECK(std::filesystem::equivalent(find_palette("fineliner12"), source_pens + "/fineliner12.toml"));
  CHECK(stipplot::load_palette("fineliner12").pens.size() == 12);
  // Paths stay paths, found or not.
  CHECK(find_palette(source_pens + "/black.toml") == source_pens + "/black.toml");
  CHECK(find_palette("nowhere/black.toml") == "nowhere/black.toml");
  CHECK(find_palette("black.toml") == "black.toml");
  // An unknown name says where it looked.
  try {
    (void)find_palette("no-such-palette");
    FAIL("an unknown palette name was accepted");
  } catch (const stipplot::UserError& e) {
    const std::string m = e.what();
    CHECK(m.find("--pens no-such-palette") != std::string::npos);
    CHECK(m.find("share/stipplot/pens") != std::string::npos);
    CHECK(m.find(source_pens) != std::string::npos);
  }
  // $STIPPLOT_PENS comes first.
  test::TempDir t;
  write_lookup_palette(t.file("fineliner12.toml"), "from-env");
  ScopedEnv env("STIPPLOT_PENS", t.path.string());
  CHECK(find_palette("fineliner12") == t.file("fineliner12.toml"));
  CHECK(stipplot::load_palette("fineliner12").pens.at(0).name == "from-env");
}

TEST_CASE("an installed stipplot finds palettes in ../share/stipplot/pens beside it", "[cli][pens]") {
  // The layout `cmake --install` makes: PREFIX/bin/stipplot and PREFIX/share/stipplot/pens.
  test::TempDir t;
  std::filesystem::create_directories(t.path / "bin");
  std::filesystem::create_directories(t.path / "share/stipplot/pens");
  std::filesystem::copy_file(STIPPLOT_BIN, t.path / "bin/stipplot");
  write_lookup_palette(t.file("share/stipplot/pens/lookup-only.toml"), "installed-pen");
  // Named fineliner12 as well: the share folder comes before the source tree's.
  write_lookup_palette(t.file("share/stipplot/pens/fineliner12.toml"), "shadowing-pen");
  for (const auto& [name, pen] : {std::pair{"lookup-only", "installed-pen"}, std::pair{"fineliner12", "shadowing-pen"}}) {
    INFO(name);
    const std::string cmd = t.file("bin/stipplot") + " hatch " + test::example("coffee.png") + " --pens " + name +
                            " --time 5min -o " + t.file("o.svg") + " --json 2>&1";
    FILE* p = ::popen(cmd.c_str(), "r");
    std::string out;
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    REQUIRE(::pclose(p) == 0);
    INFO(out);
    const auto j = nlohmann::json::parse(out);
    REQUIRE(j["layers"].size() == 1);
    CHECK(j["layers"][0]["pen"] == pen);
  }
  // The same name from the build tree's binary is the source tree's palette.
  auto r = test::run_cli("hatch " + test::example("coffee.png") + " --pens lookup-only -o " + t.file("o.svg"));
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("--pens lookup-only") != std::string::npos);
}
