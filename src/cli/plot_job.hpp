#pragma once
// How `stipplot plot` gets its job: a .gcode/.hpgl file is the job itself; a drawing
// (SVG, or an image with a method) goes through the planner and a writer for the
// profile (see plot_job.cpp).
#include <string>

#include "drivers/journal.hpp"

namespace stipplot::cli {

struct PlotJobRequest {
  std::string input, profile, job_out;
};
struct PreparedJob {
  std::string path;  // the job file streamed (and journalled as PATH.journal)
  io::Dialect dialect = io::Dialect::GCode;
  std::string profile;
};

bool is_job_file(const std::string& path);
io::Dialect dialect_of(const std::string& path);
PreparedJob prepare_job(const PlotJobRequest& r);

}  // namespace stipplot::cli
