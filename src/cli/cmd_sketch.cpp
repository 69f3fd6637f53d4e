// stipplot sketch: colour sketches with real pens by point redistribution (seed 001).
#include <memory>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "eval/fidelity.hpp"
#include "methods/palette.hpp"
#include "eval/color_difference.hpp"
#include "methods/sketch/sketch.hpp"
#include "preview/preview.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

namespace {
struct SketchArgs {
  OutputArgs out;
  PlacementArgs place;
  std::string space = "rgb";
  std::string pens_file;
  std::string cell = "auto";
  std::string mark = "1.2", edge_length = "3.5";
  std::string lighten = "auto";
  std::string preview_style = "paper";
  std::string sampler = "lds";
  std::string hsi_black = "paper";
  bool measure = false;
  double blur_cells = 2;
  sketch::SketchParams p;
};
}  // namespace

void register_sketch(CLI::App& app) {
  auto args = std::make_shared<SketchArgs>();
  CLI::App* cmd = app.add_subcommand("sketch", "Colour sketch with real pens by point redistribution");
  cmd->footer(
      "Spaces: rgb (8 pens: R G B Y M C black grey; RGB distance, the paper's d), hsi (6 hue pens + black;\n"
      "hue difference, black from saturation, marks lightened where the pixel is brighter than the pen).\n"
      "--pens FILE.toml uses your own pens with the RGB distance model (see examples/pens/).\n"
      "Each pen gets its own SVG layer; the preview averages colours where strokes overlap.\n"
      "Example: stipplot sketch photo.jpg --space rgb -o photo.svg --preview photo.png --measure\n"
      "         stipplot sketch photo.jpg --pens examples/pens/fineliner12.toml -o photo.svg");
  add_output_options(cmd, args->out);
  add_placement_options(cmd, args->place);
  auto* space_opt = cmd->add_option("--space", args->space, "rgb|hsi: the built-in pen set and probability model")
                        ->capture_default_str()->group("Sketch");
  cmd->add_option("--pens", args->pens_file, "TOML palette of your pens (RGB distance model)")->group("Sketch");
  cmd->add_option("--reach", args->p.reach, "--pens: RGB reach d of every pen (0 = distance to the nearest other pen, at most sqrt(3)/2)")
      ->capture_default_str()->group("Sketch");
  cmd->add_option("--cell", args->cell, "Sampling grid cell: mm on paper (0.6, 0.6mm), input pixels (3px), or auto: sqrt(--mark x pen width), one mark's ink per cell")
      ->capture_default_str()->group("Sketch");
  cmd->add_option("--mark", args->mark, "Stroke length where the image is flat: mm (1.2, 1.2mm), cm, in or pt")->capture_default_str()->group("Strokes");
  cmd->add_option("--edge-length", args->edge_length, "Stroke length at strong edges: mm (3.5, 3.5mm), cm, in or pt")->capture_default_str()->group("Strokes");
  cmd->add_option("--edge-low", args->p.edge_low, "Gradient (luma change per cell, 0..1) above which strokes follow the edge")
      ->capture_default_str()->group("Strokes");
  cmd->add_option("--edge-high", args->p.edge_high, "Gradient at which strokes are longest and thickest")->capture_default_str()->group("Strokes");
  cmd->add_option("--passes", args->p.max_passes, "Parallel passes of a stroke at the strongest edges (1-10)")
      ->capture_default_str()->group("Strokes");
  cmd->add_option("--hatch", args->p.hatch_deg, "Direction of flat marks in degrees, counter-clockwise from +x")
      ->capture_default_str()->group("Strokes");
  cmd->add_option("--lighten", args->lighten,
                  "auto|on|off: where the pixel is brighter than the pen, lighten its marks in the preview and thin "
                  "them in the plot (auto: on for hsi)")
      ->capture_default_str()->group("Strokes");
  cmd->add_option("--hsi-black", args->hsi_black,
                  "hsi black pen: paper (exp(-5 s), HSI saturation) or chroma (exp(-5 (max-min)), hue pens give way; "
                  "fixes dark tinted areas)")
      ->capture_default_str()->group("Sketch");
  cmd->add_option("--sampler", args->sampler,
                  "lds: points at a low-discrepancy sequence (even, as Secord); random: independent draws (clumpy)")
      ->capture_default_str()->group("Sketch");
  cmd->add_option("--seed", args->p.seed, "Random seed; the same seed gives the same drawing")->capture_default_str()->group("Sketch");
  cmd->add_option("--preview-style", args->preview_style,
                  "paper: every mark, lightened as in the paper; plot: only what the plotter draws")
      ->capture_default_str()->group("Output");
  cmd->add_flag("--measure", args->measure, "Report the mean CIEDE2000 between the blurred preview and the blurred input")
      ->group("Output");
  cmd->add_option("--blur-cells", args->blur_cells, "--measure: Gaussian blur sigma in sampling cells")
      ->capture_default_str()->group("Output");
  cmd->callback([args, space_opt] {
    auto t0 = std::chrono::steady_clock::now();
    SketchArgs& a = *args;
    a.p.space = sketch::parse_color_space(a.space);
    if (!a.pens_file.empty()) {
      if (space_opt->count() > 0 && a.p.space != sketch::ColorSpace::Rgb)
        throw UserError("--pens uses the RGB distance model; drop --space " + a.space);
      a.p.pens = load_palette(a.pens_file).pens;
      a.p.space = sketch::ColorSpace::Pens;
    } else if (a.p.reach != 0) {
      throw UserError("--reach applies to --pens palettes only (rgb and hsi use the paper's values)");
    }
    a.p.cell = a.cell == "auto" ? Length{0, false} : Length::parse(a.cell, "--cell");
    a.p.mark_mm = parse_paper_mm(a.mark, "--mark");
    a.p.edge_mm = parse_paper_mm(a.edge_length, "--edge-length");
    if (a.cell != "auto" && a.p.cell.value <= 0) throw UserError("--cell must be > 0 (or auto)");
    a.p.lighten = sketch::parse_lighten(a.lighten);
    a.p.hsi_black = sketch::parse_hsi_black(a.hsi_black);
    if (a.sampler != "lds" && a.sampler != "random")
      throw UserError("--sampler: expected lds or random, got '" + a.sampler + "'");
    a.p.sampler = a.sampler == "lds" ? sketch::SketchParams::Sampler::LowDiscrepancy : sketch::SketchParams::Sampler::Random;
    const sketch::PreviewStyle style = sketch::parse_preview_style(a.preview_style);
    require_range("--blur-cells", a.blur_cells, 0, 100);
    a.p.validate();
    Placement placement = a.place.resolve();
    a.out.validate();
    Image img = load_input(a.out);
    auto t1 = std::chrono::steady_clock::now();
    sketch::SketchResult r = sketch::sketch_strokes(img, a.p, placement);
    Drawing d = sketch::to_drawing(r);
    double method_s = seconds_since(t1);
    nlohmann::json s;
    s["command"] = "sketch";
    s["space"] = sketch::to_string(a.p.space);
    s["input"] = a.out.input;
    s["image_px"] = {img.width, img.height};
    s["grid"] = {r.grid_w, r.grid_h};
    s["cell_mm"] = r.cell_mm;
    OutputArgs svg_only = a.out;
    svg_only.preview.clear();  // the sketch has its own colour-averaging preview
    write_outputs(d, svg_only, s);
    nlohmann::json pens = nlohmann::json::array();
    size_t marks = 0;
    for (const auto& ps : r.pens) {
      size_t plotted = 0;
      for (const auto& st : ps.strokes) plotted += st.plotted;
      marks += ps.strokes.size();
      pens.push_back({{"pen", ps.pen.name}, {"m", ps.m}, {"points", ps.strokes.size()}, {"plotted", plotted}});
    }
    s["pens"] = pens;
    s["points"] = marks;
    if (!a.out.preview.empty() || a.measure) {
      Image preview = sketch::render_sketch_preview(r, a.out.preview_dpi, style);
      if (!a.out.preview.empty()) {
        write_png(preview, a.out.preview);
        s["preview"] = a.out.preview;
      }
      if (a.measure) {
        const PageTransform T = placement.transform(img.width, img.height);
        Image crop = crop_to_image(preview, T, img.width, img.height);
        const double sigma = a.blur_cells * r.cell_mm / T.mm_per_px();
        s["delta_e00"] = mean_delta_e00_blurred(img, crop, sigma);
        s["blur_sigma_px"] = sigma;
      }
    }
    s["seconds_method"] = method_s;
    s["seconds"] = seconds_since(t0);
    std::ostringstream h;
    h << "wrote " << a.out.output << ": " << s["primitives"].get<size_t>() << " strokes in " << d.layers.size()
      << (d.layers.size() == 1 ? " layer" : " layers") << " (" << sketch::to_string(a.p.space) << ", grid "
      << r.grid_w << "x" << r.grid_h << ") in " << std::fixed;
    h.precision(2);
    h << s["seconds"].get<double>() << " s";
    if (s.contains("delta_e00")) h << "; mean dE00 " << s["delta_e00"].get<double>();
    if (!a.out.preview.empty()) h << "; preview " << a.out.preview;
    report(a.out, s, h.str());
  });
}

}  // namespace stipplot::cli
