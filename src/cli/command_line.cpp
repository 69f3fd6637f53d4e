#include "cli/command_line.hpp"

#include <malloc.h>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstring>
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

void set_up_heap() {
  // One malloc arena: a helper thread (the job timer beside a writer) would otherwise grow
  // an arena of its own instead of reusing what the main thread freed (a 1M-dot export
  // peaked at 339 MB instead of 286 MB). Our threads allocate little while they run.
  mallopt(M_ARENA_MAX, 1);
  // Large blocks from the heap, and kept there when freed: a command allocates and frees
  // buffers of megabytes in turn (a plan's candidate lists and sort keys, a photo's
  // planes), and each fresh mmap is paid again page by page on first touch (~10 µs a
  // fault on a virtual machine). The heap grows 64 MB at a time (untouched: not resident).
  // The 1M-dot export: 0.5 s less system time, the peak no higher; a 12-MP stipple 0.5 s less.
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  mallopt(M_TOP_PAD, 64 << 20);
}

bool works_on_photos(const char* command) {
  for (const char* c : {"stipple", "tree", "sketch", "pointillism", "hatch", "eval"})
    if (std::strcmp(command, c) == 0) return true;
  return false;
}

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
