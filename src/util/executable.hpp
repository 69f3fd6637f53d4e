#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace stipplot {
// The folder of the running executable (/proc/self/exe, symbolic links resolved); empty
// when it cannot be read. What an installed stipplot finds its shared files relative to
// (../share/stipplot).
std::filesystem::path executable_dir();

// The path of the running executable (/proc/self/exe); throws std::runtime_error when it
// cannot be read.
std::string self_executable();

// This process's environment with glibc's malloc putting large blocks on transparent huge
// pages (GLIBC_TUNABLES glibc.malloc.hugetlb=1), unless GLIBC_TUNABLES already names that
// tunable (the user's choice stands). A 12-MP photo's planes are ~30,000 pages of 4 KB,
// each a page fault on first touch, and on a virtual machine a fault costs microseconds.
std::vector<std::string> environment_on_huge_pages();

// Runs this program again with the environment above and the same arguments, unless the
// tunable is already named (then, or if the exec fails, it returns and the caller goes
// on). glibc reads its tunables only as a process starts. Call it first in main().
void rerun_on_huge_pages(char** argv);
}  // namespace stipplot
