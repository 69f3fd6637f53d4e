#pragma once
#include <filesystem>

namespace stipplot {
// The folder of the running executable (/proc/self/exe, symbolic links resolved); empty
// when it cannot be read. What an installed stipplot finds its shared files relative to
// (../share/stipplot).
std::filesystem::path executable_dir();
}  // namespace stipplot
