#include "cli/common.hpp"

#include <cstdio>
#include <filesystem>

#include "drivers/gcode/gcode_writer.hpp"
#include "drivers/hpgl/hpgl_writer.hpp"
#include "drivers/machine.hpp"
#include "drivers/profile.hpp"
#include "plan/planner.hpp"
#include "plan/stats.hpp"
#include "svg/planned_svg.hpp"
#include "preview/preview.hpp"
#include "svg/svg_writer.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::cli {

namespace fs = std::filesystem;

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
  cmd->add_option("--page", a.page, "Paper: A5, A4, A3, A2, letter, legal, tabloid or WxHmm")
      ->capture_default_str()->group("Page");
  cmd->add_option("--margin", a.margin, "Margin on every side: mm (10, 10mm), cm, in or pt")->capture_default_str()->group("Page");
  cmd->add_flag("--landscape", a.landscape, "Long side of the page horizontal")->group("Page");
  cmd->add_option("--pen-width", a.pen_width, "Pen width: mm (0.3, 0.3mm), cm, in or pt")->capture_default_str()->group("Page");
  cmd->add_option("--dot-size", a.dot_size,
                  "Drawn dot diameter: mm (0.4, 0.4mm), cm, in, pt or input pixels (1.5px); 0 = one pen touch")
      ->capture_default_str()->group("Page");
}

void add_output_options(CLI::App* cmd, OutputArgs& a) {
  cmd->add_option("input", a.input, "Input image (PNG, JPEG, BMP, TGA)")->required();
  cmd->add_option("-o,--output", a.output,
                  "Output file: .svg (the drawing), .gcode (grbl) or .hpgl (planned for --profile)")
      ->required()->group("Output");
  cmd->add_option("--profile", a.profile, "Device profile NAME or PATH for .gcode/.hpgl (see `stipplot profiles`)")
      ->capture_default_str()->group("Output");
  add_plan_options(cmd, a.plan);
  cmd->add_option("--preview", a.preview, "Also write a preview PNG of what the pens will draw")->group("Output");
  cmd->add_option("--preview-dpi", a.preview_dpi, "Preview resolution")->capture_default_str()->group("Output");
  cmd->add_flag("--json", a.json, "Print a one-line JSON summary instead of prose")->group("Output");
  cmd->add_flag("-q,--quiet", a.quiet, "Print nothing on success")->group("Output");
  cmd->add_option("--max-pixels", a.max_pixels, "Refuse images with more pixels than this")
      ->capture_default_str()->group("Input");
}

namespace {
std::string lower_ext(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  for (auto& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}
}  // namespace

OutputKind output_kind(const std::string& path, const std::string& option) {
  std::string e = lower_ext(path);
  if (e == ".svg") return OutputKind::svg;
  if (e == ".gcode" || e == ".nc" || e == ".gc") return OutputKind::gcode;
  if (e == ".hpgl" || e == ".plt" || e == ".hpg") return OutputKind::hpgl;
  throw UserError(option + " " + path + ": unknown output type '" + e + "' (use .svg, .gcode or .hpgl)");
}

namespace {
// The profile must speak what the file is; checked before any work.
void check_profile_for(OutputKind kind, const std::string& path, const std::string& profile_name) {
  if (kind == OutputKind::svg) return;
  DeviceProfile prof = find_profile(profile_name);
  if (kind == OutputKind::gcode && prof.protocol != Protocol::grbl)
    throw UserError("-o " + path + ": profile " + prof.name + " is an HPGL plotter; write .hpgl or use a grbl profile");
  if (kind == OutputKind::hpgl && prof.protocol != Protocol::hpgl)
    throw UserError("-o " + path + ": profile " + prof.name + " speaks G-code; write .gcode or use an HPGL profile");
}
}  // namespace

void OutputArgs::validate() const {
  OutputKind kind = output_kind(output);
  check_profile_for(kind, output, profile);
  if (kind != OutputKind::svg) (void)plan.resolve();
  require_writable_dir(output);
  if (!preview.empty()) {
    if (lower_ext(preview) != ".png") throw UserError("--preview " + preview + ": the preview is a PNG file");
    require_writable_dir(preview);
  }
  require_range("--preview-dpi", preview_dpi, 10, 2400);
  if (max_pixels == 0) throw UserError("--max-pixels must be at least 1");
}

Image load_input(const OutputArgs& a) {
  LoadOptions lo;
  lo.max_pixels = a.max_pixels;
  return load_image(a.input, lo);
}

void write_planned_output(const Drawing& d, const std::string& path, const std::string& profile,
                          const PlanArgs& plan_args, bool show_travel, nlohmann::json& summary) {
  const OutputKind kind = output_kind(path);
  DeviceProfile prof = find_profile(profile);
  check_profile_for(kind, path, profile);
  PlanOptions po = plan_args.resolve();
  // The pen starts at machine zero: plan from there (in page coordinates).
  po.origin = MachineTransform(prof, d.page).page_position_of_machine_zero();
  auto t0 = std::chrono::steady_clock::now();
  Plan plan = plan_drawing(d, po);
  double plan_s = seconds_since(t0);
  auto t1 = std::chrono::steady_clock::now();
  if (kind == OutputKind::gcode) {
    write_gcode_file(plan, prof, path);
  } else if (kind == OutputKind::hpgl) {
    write_hpgl_file(plan, prof, path);
  } else {
    // the planned order is only checked against the device when it goes to one
    PlannedSvgOptions so;
    so.show_travel = show_travel;
    write_planned_svg(plan, path, so);
  }
  summary["output"] = path;
  summary["profile"] = prof.name;
  summary["plan"] = to_json(plan_stats(plan, motion_params(prof), po.origin));
  summary["seconds_plan"] = plan_s;
  summary["seconds_write"] = seconds_since(t1);
}

void write_outputs(const Drawing& d, const OutputArgs& a, nlohmann::json& summary) {
  if (output_kind(a.output) == OutputKind::svg) {
    write_svg(d, a.output);
    summary["output"] = a.output;
  } else {
    write_planned_output(d, a.output, a.profile, a.plan, false, summary);
  }
  if (!a.preview.empty()) {
    PreviewOptions po;
    po.dpi = a.preview_dpi;
    write_preview_png(d, a.preview, po);
    summary["preview"] = a.preview;
  }
  nlohmann::json layers = nlohmann::json::array();
  size_t total = 0;
  for (const auto& l : d.layers) {
    layers.push_back({{"pen", l.pen.name},
                      {"color", l.pen.color.hex()},
                      {"dots", l.dots.size()},
                      {"lines", l.lines.size()},
                      {"circles", l.circles.size()}});
    total += l.primitive_count();
  }
  summary["layers"] = layers;
  summary["primitives"] = total;
  summary["page_mm"] = {d.page.width_mm, d.page.height_mm};
}

void report(const OutputArgs& a, const nlohmann::json& summary, const std::string& human) {
  if (a.json) {
    std::printf("%s\n", summary.dump().c_str());
  } else if (!a.quiet) {
    std::printf("%s\n", human.c_str());
  }
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace stipplot::cli
