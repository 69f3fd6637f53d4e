// stipplot: photographs to pen-plotter drawings, and the plotter driver.
#include <malloc.h>

#include <cstring>

#include "cli/command_line.hpp"
#include "serve/draft_worker.hpp"

int main(int argc, char** argv) {
  // One malloc arena: a helper thread (the job timer beside a writer) would otherwise grow
  // an arena of its own instead of reusing what the main thread freed (a 1M-dot export
  // peaked at 339 MB instead of 286 MB). Our threads allocate little while they run.
  mallopt(M_ARENA_MAX, 1);
  // Large blocks from the heap, and kept there when freed: a command allocates and frees
  // buffers of megabytes in turn (a plan's candidate lists and sort keys, a photo's
  // planes), and each fresh mmap is paid again page by page on first touch (~10 µs a
  // fault on a virtual machine). The heap grows 64 MB at a time (untouched: not resident).
  // The 1M-dot export: ~0.6 s less system time, peak memory about the same.
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  mallopt(M_TOP_PAD, 64 << 20);
  // The studio's draft worker (serve/draft_worker.hpp), started by `stipplot serve` on a
  // socket as its stdin; each draft is a command line run in a fork of it.
  if (argc == 2 && std::strcmp(argv[1], stipplot::serve::kDraftWorkerArg) == 0)
    return stipplot::serve::serve_drafts(0, &stipplot::cli::run_command_line);
  return stipplot::cli::run_command_line(argc, argv);
}
