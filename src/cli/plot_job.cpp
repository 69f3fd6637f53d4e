#include "cli/plot_job.hpp"

#include <algorithm>
#include <filesystem>

#include "util/error.hpp"

namespace stipplot::cli {

static std::string lower_ext(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

bool is_job_file(const std::string& path) {
  std::string e = lower_ext(path);
  return e == ".gcode" || e == ".nc" || e == ".ngc" || e == ".g" || e == ".gc" || e == ".hpgl" || e == ".plt" ||
         e == ".hpg" || e == ".hgl";
}

io::Dialect dialect_of(const std::string& path) {
  std::string e = lower_ext(path);
  return (e == ".hpgl" || e == ".plt" || e == ".hpg" || e == ".hgl") ? io::Dialect::Hpgl : io::Dialect::GCode;
}

PlotDevice plot_device(const std::string& profile) {
  if (profile.empty()) return {};
  throw UserError("--profile needs the device profiles of the planner/writers issue; without it, give --baud/--flow");
}

PreparedJob prepare_job(const PlotJobRequest& r) {
  if (is_job_file(r.input)) return {r.input, dialect_of(r.input), r.profile};
  throw UserError("plotting " + r.input +
                  " needs the planner and the G-code/HPGL writers; give a .gcode or .hpgl job (stipplot export ... "
                  "-o job.gcode) instead");
}

}  // namespace stipplot::cli
