#pragma once
// Reads an HPGL job: splits it into instructions (at ';' and before each new mnemonic;
// LB labels run to ETX, CO comments to their closing quote) and tracks the pen (PU/PD,
// SP) and position (PA/PR) after each.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/job/job.hpp"

namespace stipplot::io {

// Throws UserError naming the byte where an instruction was expected. O(text length).
Job parse_hpgl_job(const std::string& text);

// A pause the writer planned (a pen reload) is HP-GL/2's comment instruction with a
// marker: CO"stipplot pause: MESSAGE"; (the message holds no '"' or ';'). Plotters of
// HP-GL/1 such as the 7475A do not know CO, so a streamer must not send it: it stops
// there until the operator has done what MESSAGE says.
std::string hpgl_pause_instruction(const std::string& message);
// MESSAGE if `instruction` is such a pause, else nullopt.
std::optional<std::string> hpgl_pause_message(std::string_view instruction);

// An instruction's parameters as numbers: separated by ',', ';' or whitespace, and a
// sign starts a new number ("10-20" is 10, -20), as HP-GL plotters read them.
std::vector<double> hpgl_numbers(std::string_view params);

}  // namespace stipplot::io
