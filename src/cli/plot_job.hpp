#pragma once
// How `stipplot plot` gets its job and its device: a .gcode/.hpgl file is the job
// itself; an SVG drawing is planned and written for the profile first (as `export`
// does). The device is the profile, or a generic one for the job's dialect.
#include <string>

#include "cli/layout_options.hpp"
#include "cli/pen_heights.hpp"
#include "cli/plan_options.hpp"
#include "drivers/device/profile.hpp"
#include "drivers/job/job.hpp"

namespace stipplot::cli {

struct PlotJobRequest {
  std::string input, profile, job_out;
  PlanArgs plan;      // for an SVG
  LayoutArgs layout;  // for an SVG: a job file is plotted as it is
  PenHeightArgs heights;  // for an SVG on an EBB: the job carries its servo settings
};
struct PreparedJob {
  std::string path;  // the job file streamed (and journalled as PATH.journal)
  io::Dialect dialect = io::Dialect::GCode;
  std::string profile;
  std::string layout_note;  // what laying the SVG out on the sheet did, for the log
};

bool is_job_file(const std::string& path);
io::Dialect dialect_of(const std::string& path);
PreparedJob prepare_job(const PlotJobRequest& r);

// The profile `name`, or without one (empty) a generic device for the dialect: grbl at
// 115200 baud with a 128-byte RX buffer whose pen is down while the spindle runs with
// S > 0 or Z is below 0, or an HPGL plotter at 9600 baud with a 1024-byte buffer polled
// by ESC.B; 300 x 300 mm of travel, y up, the time model's default motion.
DeviceProfile plot_profile(const std::string& name, io::Dialect dialect);

}  // namespace stipplot::cli
