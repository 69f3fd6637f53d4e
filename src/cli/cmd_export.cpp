// stipplot export: a drawing from an SVG (ours or anyone's) planned for a device and
// written as G-code, HPGL, or an SVG of the planned order.
#include <memory>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/layout_options.hpp"
#include "cli/plan_options.hpp"
#include "preview/preview.hpp"
#include "svg/svg_reader.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"
#include "util/keep_until_exit.hpp"
#include "util/output_paths.hpp"
#include "util/threads.hpp"
#include "util/units.hpp"

namespace stipplot::cli {

namespace {
struct ExportArgs {
  std::string input, output, preview;
  std::string profile = "grbl-servo";
  PlanArgs plan;
  LayoutArgs layout;
  std::string tolerance = "0.05";
  std::string pen_width = "0.3";
  bool show_travel = false;
  int threads = 0;  // 0: one per core (util/threads.hpp)
  PenHeightArgs heights;
  ReportArgs report;
};
}  // namespace

// One declaration a line, the footer's examples and the run: long only because export has
// the most options of any command; each is read where its library takes it.
void register_export(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand("export", "Plan an SVG drawing for a plotter and write G-code, HPGL or planned SVG");
  cmd->footer(
      "The SVG can come from stipplot or any drawing program: paths, lines, polylines, polygons,\n"
      "rects, circles and ellipses, filled shapes (hatched at the pen width) and text (Hershey\n"
      "single-stroke fonts); Inkscape layers (or stroke colours) become pens; curves are flattened\n"
      "within --tolerance. Layers labelled '%...' and hidden content are skipped. The drawing is laid\n"
      "on the profile's sheet (or --page), turned to its orientation; what lies off the sheet is cut off.\n"
      "To export an image, run a method with -o x.gcode / -o x.hpgl directly.\n"
      "Examples:\n"
      "  stipplot export drawing.svg --profile grbl-servo -o drawing.gcode\n"
      "  stipplot export drawing.svg --profile axidraw-v3 -o drawing.ebb   (AxiDraw: EiBotBoard commands)\n"
      "  stipplot export drawing.svg --profile axidraw-v3 -o drawing.ebb --pos-up 70 --pos-down 25\n"
      "  stipplot export drawing.svg --profile hp7475a-a4 -o drawing.hpgl --optimize-effort 2\n"
      "  stipplot export drawing.svg --profile hp7475a-a4 -o drawing.hpgl --fit --margin 15mm\n"
      "  stipplot export drawing.svg --profile hp7475a-a4 -o two.hpgl --layer 2 --pen-map red=3\n"
      "  stipplot export drawing.svg -o planned.svg --show-travel");
  cmd->add_option("input", args->input, "Input SVG")->required();
  cmd->add_option("-o,--output", args->output, "Output: .gcode, .hpgl, .ebb (EiBotBoard), or .svg (the planned order)")->required()->group("Output");
  cmd->add_option("--profile", args->profile, "Device profile NAME or PATH (see `stipplot profiles`)")
      ->capture_default_str()->group("Output");
  cmd->add_flag("--show-travel", args->show_travel, "Planned SVG: add the pen-up travel as a hidden layer")->group("Output");
  cmd->add_option("--preview", args->preview, "Also write a pen-true preview PNG of the plan: what the pens will draw on the sheet")->group("Output");
  add_report_options(cmd, args->report);
  cmd->add_option("--threads", args->threads,
                  "Threads for the parallel parts: the SVG's tokenising beside its drawing, the plan's two halves of a "
                  "large drawing (0: one per core, or OMP_NUM_THREADS if set); the output is the same for any count")
      ->capture_default_str()->group("Output");
  cmd->add_option("--tolerance", args->tolerance, "Curve flattening tolerance: mm (0.05, 0.05mm), cm, in, pt or px (1/96 in)")->capture_default_str()->group("Input");
  cmd->add_option("--pen-width", args->pen_width, "Pen width where the SVG gives no stroke width: mm (0.3, 0.3mm), cm, in, pt or px (1/96 in)")
      ->capture_default_str()->group("Input");
  add_pen_height_options(cmd, args->heights, "Output");
  add_ebb_moves_option(cmd, args->heights, "Output");
  add_plan_options(cmd, args->plan);
  add_layout_options(cmd, args->layout, true);
  cmd->callback([args] {
    auto t0 = std::chrono::steady_clock::now();
    ExportArgs& a = *args;
    set_thread_count(a.threads);
    const double tolerance_mm = parse_paper_mm(a.tolerance, "--tolerance");
    const double pen_width_mm = parse_paper_mm(a.pen_width, "--pen-width");
    require_range("--tolerance (mm)", tolerance_mm, 1e-4, 10);
    require_range("--pen-width (mm)", pen_width_mm, 0.01, 20);
    (void)output_kind(a.output);
    (void)a.plan.resolve();
    check_layout_args(a.layout);
    a.heights.check();
    DeviceProfile device = find_profile(a.profile);
    a.heights.apply(device);  // refuses them before any work on a profile that is not an EBB's
    if (!a.preview.empty()) require_png_path("--preview", a.preview);
    check_output_paths({{"input", a.input}}, {{"-o", a.output}, {"--preview", a.preview}});
    SvgReadOptions ro;
    ro.tolerance_mm = tolerance_mm;
    ro.default_pen_width_mm = pen_width_mm;
    SvgReadReport read;
    Drawing d = read_svg(a.input, ro, &read);
    if (d.primitive_count() == 0) throw UserError(a.input + ": nothing to plot (no visible shapes or text)");
    double read_s = seconds_since(t0);
    nlohmann::json s;
    s["command"] = "export";
    s["input"] = a.input;
    s["drawing_page_mm"] = {d.page.width_mm, d.page.height_mm};
    s["missing_glyphs"] = read.missing_glyphs;
    std::string laid_out;
    d = lay_out_for_device(std::move(d), a.layout, &device, -1, s, laid_out);
    if (d.primitive_count() == 0)
      throw UserError(a.input + ": nothing left to plot on the " + sheet_phrase(d.page) + " sheet (" +
                      (laid_out.empty() ? "check --layer and --crop" : laid_out) + ")");
    s["page_mm"] = {d.page.width_mm, d.page.height_mm};
    s["primitives"] = d.primitive_count();
    s["seconds_read"] = read_s;
    const size_t layers = d.layers.size();
    Plan plan = write_planned_output(std::move(d), a.output, a.profile, a.plan, a.show_travel, s, a.heights);
    if (!a.preview.empty()) {
      // What the pens will draw: the plan as written, at its pens' widths and colours.
      write_png(render_plan(plan), a.preview);
      s["preview"] = a.preview;
    }
    s["seconds"] = seconds_since(t0);
    const auto& total = s["plan"]["total"];
    std::ostringstream h;
    h.precision(1);
    h << std::fixed << "wrote " << a.output << " for " << s["profile"].get<std::string>() << ": "
      << layers_phrase(layers) << ", " << total.value("strokes", size_t{0}) << " strokes, pen down "
      << total.value("pen_down_mm", 0.0) / 1000 << " m, pen up " << total.value("pen_up_mm", 0.0) / 1000
      << " m, about " << total.value("seconds", 0.0) / 60 << " min to plot (" << s["seconds"].get<double>() << " s)";
    if (!laid_out.empty()) h << "; " << laid_out;
    if (read.missing_glyphs > 0)
      h << "; " << read.missing_glyphs << " characters of text left out (the Hershey fonts have ASCII only)";
    a.report.print(s, h.str());
    keep_until_exit(std::move(plan));  // a million strokes freed by the exit, not one by one
  });
}

}  // namespace stipplot::cli
