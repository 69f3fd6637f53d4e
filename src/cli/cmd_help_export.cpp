// stipplot help-export (hidden): the reference pages, man pages and shell completions,
// written from the option definitions of every other command (cli/docgen.hpp).
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "cli/commands.hpp"
#include "cli/docgen.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

void register_help_export(CLI::App& app) {
  struct Args {
    std::string format, dir;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "help-export", "Write the reference (Markdown), the man pages or a shell completion from the options");
  cmd->group("");  // hidden: a build and documentation tool
  cmd->footer(
      "md: DIR/README.md and DIR/<command>.md (docs/reference: scripts/gen_docs.sh); man: DIR/stipplot.1 and\n"
      "DIR/stipplot-<command>.1; bash: DIR/stipplot; zsh: DIR/_stipplot; fish: DIR/stipplot.fish");
  cmd->add_option("--format", args->format, "md|man|bash|zsh|fish")->required();
  cmd->add_option("dir", args->dir, "Folder to write into (made if missing)")->required();
  CLI::App* root = &app;
  cmd->callback([args, root] {
    const docgen::CommandDoc doc = docgen::describe(*root);
    std::map<std::string, std::string> files;
    const std::string& f = args->format;
    if (f == "md") files = docgen::markdown_pages(doc);
    else if (f == "man") files = docgen::man_pages(doc, STIPPLOT_VERSION);
    else if (f == "bash") files["stipplot"] = docgen::bash_completion(doc);
    else if (f == "zsh") files["_stipplot"] = docgen::zsh_completion(doc);
    else if (f == "fish") files["stipplot.fish"] = docgen::fish_completion(doc);
    else throw UserError("--format " + f + ": expected md, man, bash, zsh or fish");
    std::error_code ec;
    std::filesystem::create_directories(args->dir, ec);
    if (ec) throw UserError(args->dir + ": cannot make the folder: " + ec.message());
    for (const auto& [name, text] : files) write_file_atomic(std::filesystem::path(args->dir) / name, text);
  });
}

}  // namespace stipplot::cli
