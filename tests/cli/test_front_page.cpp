// README.md is a front page: short, with pictures of what each method draws, every command
// with an example, and links into docs/ that resolve. The guides' links must resolve too.
#include <catch2/catch.hpp>
#include <algorithm>
#include <filesystem>
#include <regex>
#include <set>
#include <string>

#include "cli/commands.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;

namespace {

// Relative targets of markdown links and images: ](target) without a scheme or a bare anchor.
std::vector<std::string> relative_links(const std::string& md) {
  std::vector<std::string> out;
  static const std::regex link(R"(\]\(([^)\s]+)\))");
  for (auto it = std::sregex_iterator(md.begin(), md.end(), link); it != std::sregex_iterator(); ++it) {
    std::string target = (*it)[1];
    if (target.rfind("http", 0) == 0 || target[0] == '#') continue;
    out.push_back(target.substr(0, target.find('#')));
  }
  return out;
}

}  // namespace

TEST_CASE("README is a front page: under 250 lines, a gallery of every method, every command with an example") {
  const fs::path src = STIPPLOT_SOURCE_DIR;
  const std::string readme = test::read_file((src / "README.md").string());
  CHECK(std::count(readme.begin(), readme.end(), '\n') <= 250);

  // The gallery: pictures that exist, small enough for a front page, of every method.
  std::set<std::string> images;
  static const std::regex image(R"(!\[[^\]]*\]\((docs/gallery/[^)]+)\))");
  for (auto it = std::sregex_iterator(readme.begin(), readme.end(), image); it != std::sregex_iterator(); ++it) images.insert((*it)[1]);
  CHECK(images.size() >= 10);
  for (const std::string& img : images) {
    INFO(img);
    REQUIRE(fs::exists(src / img));
    CHECK(fs::file_size(src / img) < 250 * 1024);
  }
  for (const char* method : {"stipple", "tree", "sketch", "pointillism", "hatch", "plotted"}) {
    INFO(method);
    CHECK(std::any_of(images.begin(), images.end(), [&](const std::string& i) { return i.find(method) != std::string::npos; }));
  }
  // Every command the program has, in the commands table with an example.
  CLI::App app("stipplot");
  stipplot::cli::register_all(app);
  for (CLI::App* sub : app.get_subcommands([](CLI::App* s) { return !s->get_group().empty(); })) {
    INFO(sub->get_name());
    CHECK(readme.find("`stipplot " + sub->get_name()) != std::string::npos);
  }
}

TEST_CASE("the README's and the guides' links lead to files that exist") {
  const fs::path src = STIPPLOT_SOURCE_DIR;
  std::vector<fs::path> pages = {src / "README.md"};
  for (const auto& e : fs::directory_iterator(src / "docs"))
    if (e.path().extension() == ".md") pages.push_back(e.path());
  REQUIRE(pages.size() >= 9);
  for (const fs::path& page : pages) {
    for (const std::string& target : relative_links(test::read_file(page.string()))) {
      INFO(page.filename().string() << " -> " << target);
      CHECK(fs::exists(page.parent_path() / target));
    }
  }
}
