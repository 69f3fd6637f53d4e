#pragma once
// Reads an HPGL job: splits it into instructions (at ';' and before each new mnemonic)
// and tracks the pen (PU/PD, SP) and position (PA/PR) after each.
#include <string>
#include <string_view>
#include <vector>

#include "drivers/job/job.hpp"

namespace stipplot::io {

// Throws UserError naming the byte where an instruction was expected. O(text length).
Job parse_hpgl_job(const std::string& text);

// An instruction's parameters as numbers: separated by ',', ';' or whitespace, and a
// sign starts a new number ("10-20" is 10, -20), as HP-GL plotters read them.
std::vector<double> hpgl_numbers(std::string_view params);

}  // namespace stipplot::io
