#pragma once
// Runs a stipplot command line in the benchmark's own process (no fork or exec in the
// timing) and returns what it printed on stdout, caught through a file named `tag`.
#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli/command_line.hpp"
#include "cli/commands.hpp"
#include "ratio_reporter.hpp"
#include "util/executable.hpp"

namespace bench_cli {

inline std::string run_command(const std::vector<std::string>& args, const std::string& tag) {
  static const bool heap = (stipplot::cli::set_up_heap(), true);  // as main() runs a command
  (void)heap;
  CLI::App app{"stipplot"};
  app.require_subcommand(1);
  stipplot::cli::register_all(app);
  std::vector<std::string> rev(args.rbegin(), args.rend());
  const std::string out = (std::filesystem::temp_directory_path() / ("stipplot_bench_" + tag + ".out")).string();
  std::fflush(stdout);
  const int saved = dup(STDOUT_FILENO);
  const int fd = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  dup2(fd, STDOUT_FILENO);
  close(fd);
  app.parse(rev);
  std::fflush(stdout);
  dup2(saved, STDOUT_FILENO);
  close(saved);
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace bench_cli

// A benchmark main() for photo commands: run on transparent huge pages first, as the
// stipplot main() does for them (cli::works_on_photos), then STIPPLOT_BENCH_MAIN's work.
#define STIPPLOT_BENCH_MAIN_AS_CLI(...) \
  int main(int argc, char** argv) { \
    stipplot::rerun_on_huge_pages(argv); \
    return stipplot::bench::run_benchmarks(argc, argv, std::vector<std::pair<std::string, std::string>> __VA_ARGS__); \
  }
