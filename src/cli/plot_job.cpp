#include "cli/plot_job.hpp"

#include <algorithm>
#include <filesystem>

#include "drivers/writers/gcode_writer.hpp"
#include "drivers/writers/hpgl_writer.hpp"
#include "plan/planner.hpp"
#include "svg/svg_reader.hpp"
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

DeviceProfile plot_profile(const std::string& name, io::Dialect dialect) {
  if (!name.empty()) return find_profile(name);
  const bool hpgl = dialect == io::Dialect::Hpgl;
  DeviceProfile p;
  p.protocol = hpgl ? Protocol::hpgl : Protocol::grbl;
  p.machine.travel_x_mm = p.machine.travel_y_mm = 300;
  p.machine.origin = Origin::bottom_left;
  p.machine.units_per_mm = hpgl ? 40 : 1;
  // Every G-code pen rule reads the spindle; a Z pen whose middle height is 0 adds
  // "down below Z 0", so servo, laser and Z-axis jobs all read right.
  p.pen.method = hpgl ? PenMethod::hpgl : PenMethod::z_axis;
  p.pen.z_up_mm = 1;
  p.pen.z_down_mm = -1;
  p.hpgl.handshake = HpglHandshake::buffer_query;
  p.serial.port.baud = hpgl ? 9600 : 115200;
  p.serial.rx_buffer_bytes = hpgl ? 1024 : 128;
  p.serial.newline = false;
  return p;
}

PreparedJob prepare_job(const PlotJobRequest& r) {
  if (is_job_file(r.input)) return {r.input, dialect_of(r.input), r.profile};
  if (lower_ext(r.input) != ".svg")
    throw UserError("plot takes an SVG drawing or a .gcode/.hpgl job; for an image, run a method first (e.g. "
                    "stipplot stipple photo.jpg -o photo.svg) and plot the SVG");
  DeviceProfile prof = find_profile(r.profile.empty() ? kDefaultProfile : r.profile);
  Drawing d = read_svg(r.input);
  if (d.primitive_count() == 0) throw UserError(r.input + ": nothing to plot (no visible shapes)");
  Plan plan = plan_drawing(d, PlanOptions{});
  bool hpgl = prof.protocol == Protocol::hpgl;
  std::string path = r.job_out.empty()
                         ? std::filesystem::path(r.input).replace_extension(hpgl ? ".hpgl" : ".gcode").string()
                         : r.job_out;
  if (hpgl) write_hpgl_file(plan, prof, path);
  else write_gcode_file(plan, prof, path);
  return {path, hpgl ? io::Dialect::Hpgl : io::Dialect::GCode, prof.name};
}

}  // namespace stipplot::cli
