// stipplot: photographs to pen-plotter drawings, and the plotter driver.
#include <cstring>

#include "cli/command_line.hpp"
#include "serve/draft_worker.hpp"
#include "util/executable.hpp"

int main(int argc, char** argv) {
#ifndef __SANITIZE_ADDRESS__  // ASan's own malloc reads no glibc tunables
  if (argc >= 2 && stipplot::cli::works_on_photos(argv[1])) stipplot::rerun_on_huge_pages(argv);
#endif
  stipplot::cli::set_up_heap();
  // The studio's draft worker (serve/draft_worker.hpp), started by `stipplot serve` on a
  // socket as its stdin; each draft is a command line run in a fork of it.
  if (argc == 2 && std::strcmp(argv[1], stipplot::serve::kDraftWorkerArg) == 0)
    return stipplot::serve::serve_drafts(0, &stipplot::cli::run_command_line);
  return stipplot::cli::run_command_line(argc, argv);
}
