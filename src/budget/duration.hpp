#pragma once
// Durations as users write them for --time: a number with a unit, or several summed:
// "45min", "1h", "1.5h", "90s", "1h30min", "2h 15m". Units: s, sec; m, min; h, hr.
#include <string>
#include <string_view>

namespace stipplot::budget {

// Seconds. Throws UserError naming `option` for a bare number (it needs a unit), an
// unknown unit, or a total outside 1 s .. 1000 h.
double parse_duration(std::string_view text, const char* option = "--time");

// "45 s", "12 min", "1 h 05 min": minutes rounded, seconds below two minutes.
std::string format_duration(double seconds);

}  // namespace stipplot::budget
