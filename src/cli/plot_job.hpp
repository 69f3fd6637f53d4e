#pragma once
// How `stipplot plot` gets its job: a .gcode/.hpgl file is the job itself; a drawing
// (SVG, or an image with a method) goes through the planner and a writer for the
// profile (see plot_job.cpp).
#include <string>

#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/job.hpp"
#include "drivers/motion/motion_params.hpp"

namespace stipplot::cli {

struct PlotJobRequest {
  std::string input, profile, job_out;
};
struct PreparedJob {
  std::string path;  // the job file streamed (and journalled as PATH.journal)
  io::Dialect dialect = io::Dialect::GCode;
  std::string profile;
};

// What a device profile tells the driver and the simulator (defaults without one).
struct PlotDevice {
  std::string profile;          // name, empty = none
  int baud = 0;                 // 0: protocol default
  std::string flow = "none";    // none | xonxoff | rtscts
  int rx_buffer = 0;            // grbl RX buffer / HPGL buffer; 0 = default (grbl 128; HPGL: ask)
  std::string handshake = "escb";
  bool newline = false;
  io::GcodePenRule pen;
  MotionParams motion;
  double travel_x = 300, travel_y = 300;
  double units_per_mm = 40;     // HPGL
  bool y_up = true;             // machine +Y points up the page (grbl positive space, HPGL)
};
PlotDevice plot_device(const std::string& profile);

bool is_job_file(const std::string& path);
io::Dialect dialect_of(const std::string& path);
PreparedJob prepare_job(const PlotJobRequest& r);

}  // namespace stipplot::cli
