// The reference pages, man pages and shell completions come from the CLI's own option
// definitions (stipplot help-export, cli/docgen.hpp): the checked-in docs/reference must be
// what the program says, every option must be in them, and the completions must complete.
#include <catch2/catch.hpp>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>

#include "cli/commands.hpp"
#include "cli/docgen.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;
namespace docgen = stipplot::cli::docgen;

namespace {

std::map<std::string, std::string> ref_files_in(const fs::path& dir, const std::string& ext) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ext) out[e.path().filename().string()] = test::read_file(e.path().string());
  return out;
}

std::unique_ptr<CLI::App> ref_full_app() {
  auto app = std::make_unique<CLI::App>("stipplot: turn photographs into drawings for pen plotters, and drive the plotters");
  stipplot::cli::register_all(*app);
  return app;
}

// Runs a bash snippet; its stdout.
std::string ref_sh(const std::string& script, int& status) {
  test::TempDir t;
  {
    std::ofstream f(t.file("s.sh"));
    f << script;
  }
  FILE* p = ::popen(("bash " + t.file("s.sh") + " 2>&1").c_str(), "r");
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  status = ::pclose(p);
  return out;
}

const char* kRefRegenerate = "run `bash scripts/gen_docs.sh` to regenerate docs/reference from the built program";

}  // namespace

TEST_CASE("docs/reference is what the program's options say", "[cli][docs]") {
  test::TempDir t;
  auto r = test::run_cli("help-export --format md " + t.file("md"));
  REQUIRE(r.exit_code == 0);
  const auto generated = ref_files_in(t.file("md"), ".md");
  const auto checked_in = ref_files_in(std::string(STIPPLOT_SOURCE_DIR) + "/docs/reference", ".md");
  REQUIRE(generated.size() > 10);
  for (const auto& [name, text] : generated) {
    INFO("docs/reference/" << name << ": " << kRefRegenerate);
    REQUIRE(checked_in.count(name) == 1);
    if (checked_in.at(name) != text) FAIL("docs/reference/" << name << " differs from what the program says: " << kRefRegenerate);
  }
  for (const auto& [name, text] : checked_in) {
    INFO("docs/reference/" << name << " is no command's page any more: " << kRefRegenerate);
    CHECK(generated.count(name) == 1);
  }
}

TEST_CASE("an option added without regenerating makes the reference differ", "[cli][docs]") {
  auto app_ptr = ref_full_app();
  CLI::App& app = *app_ptr;
  const auto before = docgen::markdown_pages(docgen::describe(app));
  std::string value;
  app.get_subcommand("stipple")->add_option("--brand-new", value, "An option nobody documented")->group("Stippling");
  const auto after = docgen::markdown_pages(docgen::describe(app));
  CHECK(after.at("stipple.md") != before.at("stipple.md"));
  CHECK(after.at("stipple.md").find("`--brand-new`") != std::string::npos);
  CHECK(after.at("tree.md") == before.at("tree.md"));
  // What the drift test compares against: the checked-in page is the one before.
  CHECK(test::read_file(std::string(STIPPLOT_SOURCE_DIR) + "/docs/reference/stipple.md") == before.at("stipple.md"));
}

TEST_CASE("every visible option of every command is in its reference page and man page", "[cli][docs]") {
  auto app_ptr = ref_full_app();
  CLI::App& app = *app_ptr;
  const auto doc = docgen::describe(app);
  const auto md = docgen::markdown_pages(doc);
  const auto man = docgen::man_pages(doc, "9.9");
  size_t commands = 0, options = 0;
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    const std::string name = sub->get_name();
    if (sub->get_group().empty()) {  // hidden: help-export itself
      CHECK(md.count(name + ".md") == 0);
      CHECK(man.count("stipplot-" + name + ".1") == 0);
      continue;
    }
    ++commands;
    REQUIRE(md.count(name + ".md") == 1);
    REQUIRE(man.count("stipplot-" + name + ".1") == 1);
    const std::string& page = md.at(name + ".md");
    const std::string& roff = man.at("stipplot-" + name + ".1");
    CHECK(page.find(sub->get_description()) != std::string::npos);
    CHECK(md.at("README.md").find("(" + name + ".md)") != std::string::npos);
    for (CLI::Option* o : sub->get_options([](CLI::Option* x) { return !x->get_group().empty(); })) {
      ++options;
      for (const auto& l : o->get_lnames()) {
        INFO(name << " --" << l);
        CHECK(page.find("`--" + l + "`") != std::string::npos);
        std::string escaped = "\\-\\-";
        for (char c : l) escaped += c == '-' ? std::string("\\-") : std::string(1, c);
        CHECK(roff.find("\\fB" + escaped + "\\fR") != std::string::npos);
      }
      if (!o->get_default_str().empty()) CHECK(page.find(o->get_default_str()) != std::string::npos);
    }
    // Hidden options stay out.
    for (CLI::Option* o : sub->get_options([](CLI::Option* x) { return x->get_group().empty(); }))
      for (const auto& l : o->get_lnames()) CHECK(page.find("`--" + l + "`") == std::string::npos);
  }
  CHECK(commands >= 12);
  CHECK(options > 200);
  CHECK(man.at("stipplot.1").find(".TH STIPPLOT 1 \"\" \"stipplot 9.9\"") != std::string::npos);
}

TEST_CASE("bash completion completes commands, options and their values", "[cli][docs]") {
  test::TempDir t;
  REQUIRE(test::run_cli("help-export --format bash " + t.file("c")).exit_code == 0);
  const std::string prelude = "source " + t.file("c/stipplot") + "\n";
  auto complete = [&](const std::string& words, int cword) {
    int status = 0;
    std::string out = ref_sh(prelude + "COMP_WORDS=(" + words + "); COMP_CWORD=" + std::to_string(cword) +
                             "; _stipplot; ((${#COMPREPLY[@]} == 0)) || printf '%s\\n' \"${COMPREPLY[@]}\"",
                         status);
    INFO(out);
    CHECK(status == 0);
    return out;
  };
  CHECK(complete("stipplot st", 1) == "stipple\n");
  CHECK(complete("stipplot stipple --ou", 2) == "--output\n");
  CHECK(complete("stipplot hatch --pen-w", 2) == "--pen-width\n");
  CHECK(complete("stipplot stipple -m gr", 3) == "gray\n");
  CHECK(complete("stipplot stipple --fill h", 3) == "hatch\n");
  // After an option taking a value, the next word is not taken for a command.
  CHECK(complete("stipplot plot --profile grbl-servo --sim --sim-sp", 5) == "--sim-speedup\n");
  // The program's own profiles by name.
  const std::string profiles = complete(std::string(STIPPLOT_BIN) + " stipple --profile grbl-s", 3);
  CHECK(profiles == "grbl-servo\n");
  // Hidden commands are not offered.
  CHECK(complete("stipplot help", 1) == "");
}

TEST_CASE("zsh and fish completions are valid and fish completes", "[cli][docs]") {
  test::TempDir t;
  for (const char* f : {"zsh", "fish"}) REQUIRE(test::run_cli(std::string("help-export --format ") + f + " " + t.file("c")).exit_code == 0);
  int status = 0;
  std::string out = ref_sh("command -v zsh >/dev/null || { echo 'zsh missing: bash scripts/setup.sh test'; exit 1; }\n"
                       "zsh -n " + t.file("c/_stipplot"), status);
  INFO(out);
  CHECK(status == 0);
  out = ref_sh("command -v fish >/dev/null || { echo 'fish missing: bash scripts/setup.sh test'; exit 1; }\n"
           "fish -n " + t.file("c/stipplot.fish"), status);
  CHECK(status == 0);
  out = ref_sh("HOME=" + t.path.string() + " fish -c 'source " + t.file("c/stipplot.fish") +
               "; complete -C \"stipplot stipple --ou\"; complete -C \"stipplot sti\"; complete -C \"stipplot stipple -m gr\"'",
           status);
  CHECK(status == 0);
  CHECK(out.find("--output\t") != std::string::npos);
  CHECK(out.find("stipple\tStipple an image") != std::string::npos);
  CHECK(out.find("gray") != std::string::npos);
  CHECK(out.find("help-export") == std::string::npos);
}
