#include "cli/plot_job.hpp"

#include <algorithm>
#include <filesystem>

#include "util/error.hpp"

#include "drivers/gcode/gcode_writer.hpp"
#include "drivers/hpgl/hpgl_writer.hpp"
#include "drivers/profile.hpp"
#include "plan/planner.hpp"
#include "svg/svg_reader.hpp"

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

PlotDevice plot_device(const std::string& name) {
  PlotDevice d;
  if (name.empty()) return d;
  DeviceProfile p = find_profile(name);
  d.profile = p.name;
  d.baud = p.baud;
  d.flow = p.flow_control == FlowControl::xonxoff ? "xonxoff" : p.flow_control == FlowControl::rtscts ? "rtscts" : "none";
  d.rx_buffer = p.rx_buffer_bytes;
  switch (p.hpgl_handshake) {
    case HpglHandshake::buffer_query: d.handshake = "escb"; break;
    case HpglHandshake::xonxoff: d.handshake = "xonxoff"; break;
    default: d.handshake = "hardware"; break;  // RTS/CTS in the serial driver, or none at all
  }
  d.newline = p.newline;
  if (p.pen_method == PenMethod::servo) d.pen.servo_up_s = p.servo_up_s;
  if (p.pen_method == PenMethod::z_axis) {
    if (!(p.z_down_mm < p.z_up_mm))
      throw UserError("profile " + p.name + ": the driver expects z_down_mm below z_up_mm to tell the pen state");
    d.pen.z_down_below = (p.z_up_mm + p.z_down_mm) / 2;
  } else {
    d.pen.z_down_below = -1e9;  // Z plays no part in the pen state
  }
  d.motion = motion_params(p);
  d.travel_x = p.travel_x_mm;
  d.travel_y = p.travel_y_mm;
  d.units_per_mm = p.units_per_mm;
  const bool bottom = p.origin == Origin::bottom_left;
  d.y_up = bottom == (p.y_sign > 0);
  return d;
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
