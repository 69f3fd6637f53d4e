#pragma once
// The whole program on one command line: parse, run, stage and commit the outputs, and
// turn every error into the one-line message and exit code main() returns. main() and the
// studio's draft worker (which runs commands in processes forked from it) both use it.
namespace stipplot::cli {

// argv[0] is the program's name. Returns the exit code: 0, 1 (a user's error), 70 (a bug).
int run_command_line(int argc, char** argv);

// The malloc settings the program runs with (main() sets them first): one arena, and
// large blocks from the heap, kept there when freed. A benchmark that runs commands in
// its own process sets them too, or it times another allocator's page faults.
void set_up_heap();
// The commands that work on a photo's planes (tens of MB a 12-MP photo): main() runs them
// on transparent huge pages (util/executable.hpp, rerun_on_huge_pages). A 12-MP tree took
// 0.64 s instead of 1.05 s, a stipple 2.20 s instead of 2.36 s, at the same peak. Not
// export: its peak for a million dots rose over 300 MB (the plan's blocks, 2 MB pages).
bool works_on_photos(const char* command);

}  // namespace stipplot::cli
