#pragma once
// The files a command reads and writes, checked together before any work: an output
// never overwrites an input or another output of the same run, is never a directory, and
// its directory exists and is writable. Paths are compared as the filesystem resolves
// them (symbolic links, "./a" and "a", hard links to one file).
#include <string>
#include <vector>

namespace stipplot {

struct NamedPath {
  std::string option;  // how the user named it: "-o", "--preview", "input"
  std::string path;
};

// Throws UserError naming both options, e.g. "--preview photo.png would overwrite the
// input photo.png". Empty paths (options not given) are skipped. O(n^2) in the few paths.
void check_output_paths(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs);

}  // namespace stipplot
