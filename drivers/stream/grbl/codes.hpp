#pragma once
// grbl 1.1 error and alarm codes with their meanings (from grbl's doc/csv tables).
#include <string>

namespace stipplot::io::grbl {

// "Unsupported command: unsupported or invalid g-code command found in block."
std::string error_meaning(int code);
std::string alarm_meaning(int code);

}  // namespace stipplot::io::grbl
