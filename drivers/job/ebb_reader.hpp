#pragma once
// Reads an EiBotBoard job (drivers/writers/ebb_writer.hpp): one firmware command a line,
// tracking the motors (SM and LM steps, zeroed by EM) and the pen (SP) after each (the job timer,
// time_ebb_job, adds each command's firmware time). Positions are
// machine mm from the motors: x = (m1 + m2) / 2, y = (m1 - m2) / 2 over steps_per_mm.
// Lines starting with '#' are the host's (never sent); "# pause: NOTE" is a pause.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/job/job.hpp"

namespace stipplot::io {

// What one EBB command does, as far as a job is concerned.
struct EbbCommand {
  std::string name;  // "SM", "LM", "SP", "EM", "SC", ... (upper case)
  std::vector<long long> args;
  int64_t ms = 0;            // SM duration, SP delay
  int64_t ticks = 0;         // firmware time in 40 µs ticks (SM, SP: ms * 25; LM: lm_ticks)
  int64_t s1 = 0, s2 = 0;    // SM and LM steps
  int pen = -1;              // SP: 1 up, 0 down
};
// Parses "SM,25,10,-3" or "LM,<r1>,<s1>,<a1>,<r2>,<s2>,<a2>[,<clear>]"; throws UserError
// naming the line for anything else than the commands a job may hold (SM LM SP EM SC CU),
// numbers out of the firmware's range, or an LM that would stall or reverse (its rate
// reaching 0 before its last step). An LM's time is the firmware's with its accumulators
// cleared (clear 3, as the writer sends it); without, the board's carried-over step
// fractions make it end up to a step earlier. O(1).
EbbCommand parse_ebb_command(std::string_view text, size_t line_no);
// Whether a command (by its name) moves the motors: SM or LM.
bool ebb_motion_command(std::string_view name);

// A command's name: the text before its first comma, upper case ("sm,10,1,1" -> "SM").
std::string ebb_command_name(std::string_view text);

// Throws UserError naming the first bad line. O(text length).
Job parse_ebb_job(const std::string& text, double steps_per_mm);

std::string ebb_pause_line(const std::string& note);
std::optional<std::string> ebb_pause_note(std::string_view line);

// Motor steps of a job position (mm), the inverse of the reader's mixing: exact for
// every position a job reaches.
std::array<int64_t, 2> ebb_motor_steps(double x_mm, double y_mm, double steps_per_mm);

}  // namespace stipplot::io
