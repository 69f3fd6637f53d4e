// stipplot: photographs to pen-plotter drawings, and the plotter driver.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <new>

#include "cli/commands.hpp"
#include "util/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"stipplot: turn photographs into drawings for pen plotters, and drive the plotters"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "stipplot 0.1.0");
  stipplot::cli::register_all(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const stipplot::UserError& e) {
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
