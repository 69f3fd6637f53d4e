#include "cli/plot_job.hpp"

#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli/common.hpp"
#include "svg/svg_reader.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

bool is_job_file(const std::string& path) {
  auto k = kind_of_file(path);
  return k && *k != OutputKind::svg;
}

io::Dialect dialect_of(const std::string& path) {
  const auto k = kind_of_file(path);
  return k == OutputKind::hpgl ? io::Dialect::Hpgl : k == OutputKind::ebb ? io::Dialect::Ebb : io::Dialect::GCode;
}

namespace {
io::Dialect dialect_for(const DeviceProfile& p) {
  return p.protocol == Protocol::hpgl ? io::Dialect::Hpgl : p.protocol == Protocol::ebb ? io::Dialect::Ebb : io::Dialect::GCode;
}
const char* extension_of(io::Dialect d) { return d == io::Dialect::Hpgl ? ".hpgl" : d == io::Dialect::Ebb ? ".ebb" : ".gcode"; }
}  // namespace

DeviceProfile plot_profile(const std::string& name, io::Dialect dialect) {
  if (!name.empty()) return find_profile(name);
  if (dialect == io::Dialect::Ebb) return find_profile("axidraw-v3");  // EBB jobs are in its steps
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

namespace {
// write_planned_output picks the writer by the file's extension: it must be the profile's.
void check_job_name(const std::string& path, const DeviceProfile& prof) {
  const io::Dialect d = dialect_for(prof);
  bool ok = false;
  try {
    ok = output_kind(path, "--job") != OutputKind::svg && dialect_of(path) == d;
  } catch (const UserError&) {
  }
  if (!ok)
    throw UserError("--job " + path + ": profile " + prof.name +
                    (d == io::Dialect::Hpgl  ? " is an HPGL plotter: name the job .hpgl or .plt"
                     : d == io::Dialect::Ebb ? " is an EiBotBoard machine: name the job .ebb"
                                             : " speaks G-code: name the job .gcode or .nc"));
}
}  // namespace

PreparedJob prepare_job(const PlotJobRequest& r) {
  if (is_job_file(r.input)) {
    if (r.layout.any_given())
      throw UserError("layout and layer options apply to an SVG drawing; " + r.input + " is a finished job, plotted as it is");
    if (r.heights.any_given())
      throw UserError("--pos-up/--pos-down apply to an SVG drawing; " + r.input +
                      " is a finished job with its own servo settings (export it again with them)");
    if (r.heights.moves_opt && r.heights.moves_opt->count() > 0)
      throw UserError("--ebb-moves applies to an SVG drawing; " + r.input +
                      " is a finished job with its own moves (export it again with --ebb-moves)");
    return {r.input, dialect_of(r.input), r.profile, {}};
  }
  if (!has_extension(r.input, ".svg"))
    throw UserError("plot takes an SVG drawing or a .gcode/.hpgl/.ebb job; for an image, run a method first (e.g. "
                    "stipplot stipple photo.jpg -o photo.svg) and plot the SVG");
  const std::string profile = r.profile.empty() ? kDefaultProfile : r.profile;
  DeviceProfile prof = find_profile(profile);
  r.heights.apply(prof);  // refused before any work on a profile that is not an EBB's
  check_layout_args(r.layout);
  (void)r.plan.resolve();
  Drawing d = read_svg(r.input);
  if (d.primitive_count() == 0) throw UserError(r.input + ": nothing to plot (no visible shapes or text)");
  nlohmann::json plan_summary;  // plot reports the streaming, not the plan
  std::string note;
  d = lay_out_for_device(std::move(d), r.layout, &prof, -1, plan_summary, note);
  if (d.primitive_count() == 0) throw UserError(r.input + ": nothing left to plot on the sheet (" + note + ")");
  const io::Dialect dialect = dialect_for(prof);
  std::string path = r.job_out.empty() ? std::filesystem::path(r.input).replace_extension(extension_of(dialect)).string()
                                       : r.job_out;
  if (!r.job_out.empty()) check_job_name(path, prof);
  write_planned_output(d, path, profile, r.plan, false, plan_summary, r.heights);
  commit_staged_outputs();  // streamed from the file
  return {path, dialect, prof.name, note};
}

}  // namespace stipplot::cli
