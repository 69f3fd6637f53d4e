#pragma once
// The whole program on one command line: parse, run, stage and commit the outputs, and
// turn every error into the one-line message and exit code main() returns. main() and the
// studio's draft worker (which runs commands in processes forked from it) both use it.
namespace stipplot::cli {

// argv[0] is the program's name. Returns the exit code: 0, 1 (a user's error), 70 (a bug).
int run_command_line(int argc, char** argv);

}  // namespace stipplot::cli
