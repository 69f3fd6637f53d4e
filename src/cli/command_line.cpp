#include "cli/command_line.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <new>
#include <string>

#include "cli/commands.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

namespace {
// CLI11's messages may span lines; the error is one.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}
}  // namespace

int run_command_line(int argc, char** argv) {
  CLI::App app{"stipplot: turn photographs into drawings for pen plotters, and drive the plotters"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "stipplot " STIPPLOT_VERSION);
  register_all(app);
  // Every file a command writes is staged and appears only once the command succeeded;
  // leaving here any other way removes the temporaries.
  OutputBatch outputs;
  try {
    app.parse(argc, argv);
    outputs.commit();
  } catch (const CLI::ParseError& e) {
    // --help and --version arrive as ParseErrors with exit code 0: CLI11 prints them.
    if (e.get_exit_code() == 0) return app.exit(e);
    std::fprintf(stderr, "stipplot: error: %s (see --help)\n", one_line(e.what()).c_str());
    return 1;
  } catch (const UserError& e) {
    std::fprintf(stderr, "stipplot: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "stipplot: error: out of memory (try a smaller image or --max-pixels)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stipplot: internal error: %s\n", e.what());
    return 70;
  }
  return 0;
}

}  // namespace stipplot::cli
