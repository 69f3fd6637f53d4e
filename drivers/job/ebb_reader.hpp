#pragma once
// Reads an EiBotBoard job (drivers/writers/ebb_writer.hpp): one firmware command a line,
// tracking the motors (SM steps, zeroed by EM) and the pen (SP) after each (the job timer,
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
  std::string name;  // "SM", "SP", "EM", "SC", ... (upper case)
  std::vector<long long> args;
  int64_t ms = 0;            // firmware time (SM duration, SP delay)
  int64_t s1 = 0, s2 = 0;    // SM steps
  int pen = -1;              // SP: 1 up, 0 down
};
// Parses "SM,25,10,-3"; throws UserError naming the line for anything else than the
// commands a job may hold (SM SP EM SC CU), or numbers out of the firmware's range.
EbbCommand parse_ebb_command(std::string_view text, size_t line_no);

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
