#include "cli/common.hpp"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "cli/job_estimate.hpp"
#include "drivers/writers/ebb_writer.hpp"
#include "drivers/writers/gcode_writer.hpp"
#include "drivers/writers/hpgl_writer.hpp"
#include "drivers/device/machine.hpp"
#include "drivers/device/profile.hpp"
#include "plan/planner.hpp"
#include "drivers/motion/plan_stats.hpp"
#include "svg/planned_svg.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::cli {

Placement PlacementArgs::resolve() const {
  Placement p;
  p.page = parse_page(page);
  p.margin_mm = parse_paper_mm(margin, "--margin");
  p.landscape = landscape;
  p.pen_width_mm = parse_paper_mm(pen_width, "--pen-width");
  p.dot_size = Length::parse(dot_size, "--dot-size");
  p.validate();
  return p;
}

void add_placement_options(CLI::App* cmd, PlacementArgs& a) {
  cmd->add_option("--page", a.page, "Paper: A5, A4, A3, A2, letter, legal, tabloid or WxH (210x297mm, 30x20cm, 11x8.5in)")
      ->capture_default_str()->group("Page");
  cmd->add_option("--margin", a.margin, "Margin on every side: mm (10, 10mm), cm, in, pt or px (1/96 in)")->capture_default_str()->group("Page");
  cmd->add_flag("--landscape", a.landscape, "Long side of the page horizontal")->group("Page");
  cmd->add_option("--pen-width", a.pen_width, "Pen width: mm (0.3, 0.3mm), cm, in, pt or px (1/96 in)")->capture_default_str()->group("Page");
  cmd->add_option("--dot-size", a.dot_size,
                  "Drawn dot diameter on paper (0.4mm) or in input pixels (1.5px); 0 = one pen touch")
      ->capture_default_str()->group("Page");
}

void ReportArgs::print(const nlohmann::json& summary, const std::string& sentence) const {
  if (json) {
    std::printf("%s\n", summary.dump().c_str());
  } else if (!quiet) {
    std::printf("%s\n", sentence.c_str());
  }
}

void add_report_options(CLI::App* cmd, ReportArgs& a) {
  cmd->add_flag("--json", a.json, "Print a one-line JSON summary instead of prose")->group("Output");
  cmd->add_flag("-q,--quiet", a.quiet, "Print nothing on success")->group("Output");
}

namespace {
std::string lower_extension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (auto& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}
}  // namespace

bool has_extension(const std::string& path, const char* ext) { return lower_extension(path) == ext; }

void require_png_path(const std::string& option, const std::string& path) {
  if (!has_extension(path, ".png")) throw UserError(option + " " + path + ": expected a .png file");
  require_writable_dir(path);
}

std::optional<OutputKind> kind_of_file(const std::string& path) {
  const std::string e = lower_extension(path);
  if (e == ".svg") return OutputKind::svg;
  if (e == ".gcode" || e == ".nc" || e == ".ngc" || e == ".gc" || e == ".g") return OutputKind::gcode;
  if (e == ".hpgl" || e == ".plt" || e == ".hpg" || e == ".hgl") return OutputKind::hpgl;
  if (e == ".ebb") return OutputKind::ebb;
  return std::nullopt;
}

OutputKind output_kind(const std::string& path, const std::string& option) {
  if (auto k = kind_of_file(path)) return *k;
  throw UserError(option + " " + path + ": unknown output type '" + lower_extension(path) +
                  "' (use .svg, .gcode, .hpgl or .ebb)");
}

void check_profile_for(OutputKind kind, const std::string& path, const std::string& profile_name) {
  if (kind == OutputKind::svg) return;
  DeviceProfile prof = find_profile(profile_name);
  static const char* kExt[] = {"", ".gcode", ".hpgl", ".ebb"};
  static const char* kWhat[] = {"", "speaks G-code (grbl)", "is an HPGL plotter", "is an EiBotBoard (AxiDraw) machine"};
  const OutputKind wants = prof.protocol == Protocol::grbl ? OutputKind::gcode
                           : prof.protocol == Protocol::hpgl ? OutputKind::hpgl
                                                              : OutputKind::ebb;
  if (kind != wants) {
    const int w = static_cast<int>(wants);
    throw UserError("-o " + path + ": profile " + prof.name + " " + kWhat[w] + "; write " + kExt[w] +
                    " or choose a profile for this file type");
  }
}

PlanOptions plan_options_for(const DeviceProfile& profile, const Page& page, const PlanArgs& plan_args) {
  PlanOptions po = plan_args.resolve();
  po.origin = MachineTransform(profile, page).page_position_of_machine_zero();
  return po;
}

namespace {
// About a line a point and five a stroke (travel, pen down and up with their waits).
size_t job_lines_hint(const Plan& plan) {
  size_t lines = 64;
  for (const PlannedLayer& l : plan.layers)
    for (const Stroke& s : l.strokes) lines += s.pts.size() + 5;
  return lines;
}
}  // namespace

void time_as_job(const Plan& plan, const DeviceProfile& profile, nlohmann::json& plan_summary) {
  JobEstimate timed(profile, job_lines_hint(plan));
  const LineSink nowhere = [](std::string_view) {};
  if (profile.protocol == Protocol::grbl)
    write_gcode(plan, profile, nowhere, timed.gcode_options());
  else if (profile.protocol == Protocol::ebb)
    write_ebb(plan, profile, nowhere, timed.ebb_options());
  else
    write_hpgl(plan, profile, nowhere, timed.hpgl_options());
  timed.apply(plan_summary);
}

bool link_may_bind(const Plan& plan, double plan_seconds, const DeviceProfile& profile) {
  const double lines_per_s = profile.serial.port.baud / 10.0 / 20.0;
  return plan_seconds > 0 && static_cast<double>(job_lines_hint(plan)) / plan_seconds > 0.25 * lines_per_s;
}

void write_plan_file(const Plan& plan, const std::string& path, const DeviceProfile& profile, bool show_travel,
                     nlohmann::json* plan_summary) {
  const OutputKind kind = output_kind(path);
  // The written lines' own time, not the plan's.
  JobEstimate timed(profile, job_lines_hint(plan));
  if (kind == OutputKind::gcode) {
    write_gcode_file(plan, profile, path, timed.gcode_options());
    if (plan_summary) timed.apply(*plan_summary);
  } else if (kind == OutputKind::hpgl) {
    write_hpgl_file(plan, profile, path, timed.hpgl_options());
    if (plan_summary) timed.apply(*plan_summary);
  } else if (kind == OutputKind::ebb) {
    write_ebb_file(plan, profile, path, timed.ebb_options());
    if (plan_summary) timed.apply(*plan_summary);
  } else {
    // the planned order is only checked against the device when it goes to one
    PlannedSvgOptions so;
    so.show_travel = show_travel;
    write_planned_svg(plan, path, so);
  }
}

namespace {
// `owned`: `d` itself when the caller gave it up, else null.
Plan plan_and_write(const Drawing& d, Drawing* owned, const std::string& path, const std::string& profile,
                    const PlanArgs& plan_args, bool show_travel, nlohmann::json& summary,
                    const PenHeightArgs& heights) {
  const OutputKind kind = output_kind(path);
  DeviceProfile prof = find_profile(profile);
  heights.apply(prof);
  check_profile_for(kind, path, profile);
  const PlanOptions po = plan_options_for(prof, d.page, plan_args);
  auto t0 = std::chrono::steady_clock::now();
  PlanInfo plan_info;
  Plan plan = owned ? plan_drawing(std::move(*owned), po, &plan_info) : plan_drawing(d, po, &plan_info);
  double plan_s = seconds_since(t0);
  auto t1 = std::chrono::steady_clock::now();
  summary["output"] = path;
  summary["profile"] = prof.name;
  if (heights.any_given()) summary["pen_heights_pct"] = {prof.pen.pos_up_pct, prof.pen.pos_down_pct};
  // A G-code or EBB job ends with the pen back at machine zero, an HPGL job where it stops.
  // A device's job has its written lines timed (write_plan_file): the plan's own model
  // only times a planned SVG.
  const bool home = kind == OutputKind::gcode || kind == OutputKind::ebb;
  summary["plan"] = to_json(kind == OutputKind::svg ? plan_stats(plan, prof.motion, po.origin, home)
                                                    : plan_lengths(plan, po.origin, home));
  write_plan_file(plan, path, prof, show_travel, &summary["plan"]);
  summary["seconds_plan"] = plan_s;
  // Only a tripped --optimize-seconds cap makes the plan depend on the machine's speed.
  summary["plan_capped"] = plan_info.budget_hit;
  summary["seconds_write"] = seconds_since(t1);
  return plan;
}
}  // namespace

Plan write_planned_output(const Drawing& d, const std::string& path, const std::string& profile,
                          const PlanArgs& plan_args, bool show_travel, nlohmann::json& summary,
                          const PenHeightArgs& heights) {
  return plan_and_write(d, nullptr, path, profile, plan_args, show_travel, summary, heights);
}

Plan write_planned_output(Drawing&& d, const std::string& path, const std::string& profile,
                          const PlanArgs& plan_args, bool show_travel, nlohmann::json& summary,
                          const PenHeightArgs& heights) {
  return plan_and_write(d, &d, path, profile, plan_args, show_travel, summary, heights);
}

std::string layers_phrase(size_t n) { return std::to_string(n) + (n == 1 ? " layer" : " layers"); }

std::string sheet_phrase(const Page& page) {
  std::ostringstream s;
  s << page.width_mm << " x " << page.height_mm << " mm";
  return s.str();
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace stipplot::cli
