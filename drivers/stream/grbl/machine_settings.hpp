#pragma once
// grbl's own motion settings ($$) against the profile's. They change only the plot's
// time (grbl converts millimetres with its own $100/$101, and limits speed and
// acceleration with its own $110-$122), so a difference is a warning, and the job is
// timed again from the machine's numbers; the settings that make a plot wrong (soft
// limits, laser mode) are Streamer::check_settings' errors.
#include <map>
#include <string>
#include <vector>

#include "drivers/motion/grbl_motion.hpp"

namespace stipplot::io::grbl {

struct SettingsComparison {
  motion::GrblSettings machine;            // the profile's, with every value grbl reported
  std::vector<std::string> time_changes;   // "$120=10 mm/s^2 (the profile: 1500)"
  bool changes_time() const { return !time_changes.empty(); }
};

// Compares $100-$102, $110-$112, $120-$122, $11 and $1 (a difference over 0.5 %, or
// any for $1). O(settings).
SettingsComparison compare_motion_settings(const std::map<int, double>& reported, const motion::GrblSettings& expected);

}  // namespace stipplot::io::grbl
