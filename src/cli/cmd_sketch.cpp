// stipplot sketch: colour sketches with real pens by point redistribution (seed 001).
#include <cmath>
#include <memory>

#include "cli/commands.hpp"
#include "cli/method_command.hpp"
#include "cli/pen_choice.hpp"
#include "eval/color_difference.hpp"
#include "methods/palette.hpp"
#include "budget/mark_costs.hpp"
#include "methods/sketch/link.hpp"
#include "methods/sketch/sketch.hpp"
#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::cli {

namespace {
struct SketchArgs {
  std::string space = "rgb";
  std::string pens_file;
  std::string cell = "auto";
  std::string mark = "1.2", edge_length = "3.5";
  std::string lighten = "auto";
  std::string preview_style = "pen";  // pen: the pen-true render of the plan
  std::string sampler = "lds";
  std::string hsi_black = "paper";
  bool measure = false;
  double blur_cells = 2;
  sketch::SketchParams p;
  sketch::PreviewStyle style = sketch::PreviewStyle::Paper;
  bool space_given = false;
  int max_pens = -1;  // not given
  bool separate = false;
  sketch::LinkParams link;
  std::string ground = "auto";  // auto | hatch | none
};

// Options to parameters, before any work.
void resolve(SketchArgs& a) {
  a.p.space = sketch::parse_color_space(a.space);
  if (!a.pens_file.empty()) {
    if (a.space_given && a.p.space != sketch::ColorSpace::Rgb)
      throw UserError("--pens uses the RGB distance model; drop --space " + a.space);
    a.p.pens = load_palette(a.pens_file).pens;
    a.p.space = sketch::ColorSpace::Pens;
  } else if (a.p.reach != 0) {
    throw UserError("--reach applies to --pens palettes only (rgb and hsi use the paper's values)");
  }
  a.p.cell = a.cell == "auto" ? Length{0, false} : Length::parse(a.cell, "--cell");
  if (a.cell != "auto" && a.p.cell.value <= 0) throw UserError("--cell must be > 0 (or auto)");
  a.p.mark_mm = parse_paper_mm(a.mark, "--mark");
  a.p.edge_mm = parse_paper_mm(a.edge_length, "--edge-length");
  a.p.lighten = sketch::parse_lighten(a.lighten);
  a.p.hsi_black = sketch::parse_hsi_black(a.hsi_black);
  if (a.sampler != "lds" && a.sampler != "random")
    throw UserError("--sampler: expected lds or random, got '" + a.sampler + "'");
  a.p.sampler = a.sampler == "lds" ? sketch::SketchParams::Sampler::LowDiscrepancy : sketch::SketchParams::Sampler::Random;
  if (a.preview_style != "pen") a.style = sketch::parse_preview_style(a.preview_style);
  require_range("--blur-cells", a.blur_cells, 0, 100);
  a.link.validate();
  if (a.ground != "auto" && a.ground != "hatch" && a.ground != "none")
    throw UserError("--ground: unknown style '" + a.ground + "' (use auto, hatch or none)");
  check_max_pens(a.max_pens, a.pens_file.empty() ? 0 : a.p.pens.size(), a.pens_file);
  a.p.validate();
}

MethodResult draw(const SketchArgs& a, const MethodInput& in, std::shared_ptr<const sketch::SketchResult>* keep) {
  sketch::SketchParams p = a.p;
  PenChoice choice;
  if (a.max_pens > 0) {
    // The strokes depend on the pens (each pen's probability): one small sketch a set.
    const SearchInput search = reduced_input(in, greedy_pen_evaluations(p.pens.size(), static_cast<size_t>(a.max_pens)));
    choice = choose_pens(a.p.pens, static_cast<size_t>(a.max_pens), search, [&](const std::vector<Pen>& set) {
      sketch::SketchParams q = a.p;
      q.pens = set;
      return sketch::to_drawing(sketch::sketch_strokes(search.image, q, search.placement));
    });
    p.pens = choice.pens;
  }
  auto r = std::make_shared<sketch::SketchResult>(sketch::sketch_strokes(in.image, p, in.placement));
  *keep = r;
  MethodResult out;
  out.drawing = sketch::to_drawing(*r);
  nlohmann::json& s = out.summary;
  s["space"] = sketch::to_string(a.p.space);
  s["grid"] = {r->grid_w, r->grid_h};
  s["cell_mm"] = r->cell_mm;
  nlohmann::json pens = nlohmann::json::array();
  size_t marks = 0;
  for (const auto& ps : r->pens) {
    size_t plotted = 0;
    for (const auto& st : ps.strokes) plotted += st.plotted;
    marks += ps.strokes.size();
    pens.push_back({{"pen", ps.pen.name}, {"m", ps.m}, {"points", ps.strokes.size()}, {"plotted", plotted}});
  }
  s["pens"] = pens;
  s["points"] = marks;
  // The sketch's own previews on request; by default the pen-true render of the plan,
  // which is what the plotter draws.
  if (a.preview_style != "pen")
    out.render_preview = [r, style = a.style](double dpi) { return sketch::render_sketch_preview(*r, dpi, style); };
  if (a.measure) {
    out.measure = [r, blur_cells = a.blur_cells](MethodRun& run) {
      const double sigma = blur_cells * r->cell_mm / run.transform.mm_per_px();
      const double de = mean_delta_e00_blurred(run.input, run.preview_over_image(), sigma);
      run.summary["delta_e00"] = de;
      run.summary["blur_sigma_px"] = sigma;
      run.note("mean dE00", de);
    };
  }
  out.counts = std::to_string(out.drawing.primitive_count()) + " strokes in " + layers_phrase(out.drawing.layers.size()) +
               " (" + sketch::to_string(a.p.space) + ", grid " + std::to_string(r->grid_w) + "x" +
               std::to_string(r->grid_h) + ")";
  if (a.max_pens > 0) report_pen_choice(choice, out);
  return out;
}
// Linked after thinning: the budget keeps a share k of the marks, and those are joined.
// Linking saves pen lifts, so the thinned marks' time (k x the full drawing's)
// over-predicts; the pilot at the first knob scales it.
void link_scribbles(const SketchArgs& a, const MethodInput& in,
                    const std::shared_ptr<const sketch::SketchResult>& result, MethodDraft& d) {
  auto thinned = d.draw;
  auto cache = std::make_shared<std::pair<double, MethodResult>>(-1, MethodResult{});
  auto linked = [link = a.link, thinned, result, cache](double k) {
    if (cache->first == k) return cache->second;
    MethodResult r = thinned(k);
    sketch::LinkStats st;
    r.drawing = sketch::link_strokes(*result, r.drawing, std::clamp(k, 1e-6, 1.0), link, &st);
    r.summary["linked"] = {{"strokes", st.strokes}, {"lines", st.lines}, {"links", st.links}, {"link_mm", st.link_mm}};
    r.counts += ", linked into " + std::to_string(st.lines) + " lines";
    *cache = {k, r};
    return r;
  };
  auto scale = std::make_shared<double>(1.0);
  auto predict = d.predict;
  d.predict = [predict, scale](double k) { return *scale * predict(k); };
  d.calibrate = [linked, predict, scale, &in](double k) {
    const double thin_s = predict(k);
    if (!(thin_s > 0)) return;
    const double s = budget::quick_estimate_seconds(linked(k).drawing, in.costs.motion(), in.costs.plan_options());
    *scale = std::clamp(s / thin_s, 0.01, 1.0);
  };
  d.draw = linked;
}

// The ground beneath the strokes: at knob k its fields hatched k as dense and the share
// k^5 of the strokes over it, so a short budget goes to the tone first (a stroke is a pen
// lift for a few millimetres of ink) and the full drawing comes back at k = 1. auto: only
// where the strokes alone do not fit the budget (when the time allows it, the paper's
// sketch). The time at k predicted as k of the ground's share of the full drawing's and
// k^5 of the strokes'.
MethodDraft ground_beneath(const SketchArgs& a, const MethodInput& in, const sketch::SketchResult& result,
                           MethodDraft d) {
  const budget::MarkCosts& c = in.costs;
  auto strokes = d.draw;
  const double strokes_s = budget::quick_estimate_seconds(strokes(1).drawing, c.motion(), c.plan_options());
  if (a.ground == "auto" && (in.budget_s <= 0 || strokes_s <= in.budget_s)) return d;
  std::vector<Pen> pens;
  for (const auto& ps : result.pens) pens.push_back(ps.pen);
  auto grid = std::make_shared<const hatch::PenGrid>(sketch::ground_grid(in.image, pens, in.placement));
  constexpr double kStrokePower = 5;
  auto draw = [strokes, grid, pens, &in](double k) {
    const double kk = std::clamp(k, 1e-3, 1.0);
    MethodResult r = strokes(std::pow(kk, kStrokePower));
    Drawing g = sketch::ground_drawing(*grid, pens, in.placement, kk);
    size_t lines = 0;
    for (const Layer& l : g.layers) lines += l.lines.size();
    // Each pen's ground first, its strokes over it (merge_layers_by_pen keeps the order).
    for (Layer& l : r.drawing.layers) g.layers.push_back(std::move(l));
    r.drawing.layers = std::move(g.layers);
    r.summary["ground"] = {{"style", "hatch"}, {"coverage", kk}, {"lines", lines}};
    r.counts += " over a hatched ground of " + std::to_string(lines) + " lines";
    return r;
  };
  const double ground_s =
      budget::quick_estimate_seconds(sketch::ground_drawing(*grid, pens, in.placement, 1), c.motion(), c.plan_options());
  const double w = ground_s + strokes_s > 0 ? ground_s / (ground_s + strokes_s) : 1;
  return scaled_density(in, draw, [w](double k) { return w * k + (1 - w) * std::pow(k, kStrokePower); });
}
}  // namespace

void register_sketch(CLI::App& app) {
  auto args = std::make_shared<SketchArgs>();
  auto m = MethodCommand::add(
      app, "sketch", "Colour sketch with real pens by point redistribution",
      "Spaces: rgb (8 pens: R G B Y M C black grey; RGB distance, the paper's d), hsi (6 hue pens + black;\n"
      "hue difference, black from saturation, marks lightened where the pixel is brighter than the pen).\n"
      "--pens FILE.toml uses your own pens with the RGB distance model (see examples/pens/).\n"
      "--max-pens N (with --pens) draws with the N pens of the palette that reproduce the photo best.\n"
      "Each pen gets its own SVG layer, light pens first; the preview averages colours where strokes overlap.\n"
      "Example: stipplot sketch photo.jpg --space rgb -o photo.svg --preview photo.png --measure\n"
      "         stipplot sketch photo.jpg --pens examples/pens/fineliner12.toml -o photo.svg");
  CLI::App* cmd = m->cli();
  auto* space_opt = cmd->add_option("--space", args->space, "rgb|hsi: the built-in pen set and probability model")
                        ->capture_default_str()->group("Sketch");
  cmd->add_option("--pens", args->pens_file, "TOML palette of your pens (RGB distance model)")->group("Sketch");
  add_max_pens_option(cmd, args->max_pens);
  cmd->add_option("--reach", args->p.reach, "--pens: RGB reach d of every pen (0 = distance to the nearest other pen, at most sqrt(3)/2)")
      ->capture_default_str()->group("Sketch");
  cmd->add_option("--cell", args->cell, "Sampling grid cell: on paper (0.6mm), in input pixels (3px), or auto: sqrt(--mark x pen width), one mark's ink per cell")
      ->capture_default_str()->group("Sketch");
  cmd->add_option("--mark", args->mark, "Stroke length where the image is flat: mm (1.2, 1.2mm), cm, in, pt or px (1/96 in)")->capture_default_str()->group("Strokes");
  cmd->add_option("--edge-length", args->edge_length, "Stroke length at strong edges: mm (3.5, 3.5mm), cm, in, pt or px (1/96 in)")->capture_default_str()->group("Strokes");
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
  cmd->add_flag("--separate", args->separate,
                "Draw every stroke on its own (a pen lift each) instead of linking a pen's strokes into scribbles")
      ->group("Strokes");
  cmd->add_option("--ground", args->ground,
                  "hatch: beneath the strokes, the photo's colour fields hatched a pen each (the tone in long "
                  "pen-downs; a short --time thins the strokes first); none: the strokes on white paper (the paper's "
                  "sketch); auto: hatch where the strokes alone take longer than --time")
      ->capture_default_str()
      ->group("Strokes");
  cmd->add_option("--link-length", args->link.lift_length,
                  "Join consecutive strokes of a pen, pen down, where the link is at most this many local spacings of "
                  "its marks ...")
      ->capture_default_str()->group("Strokes");
  cmd->add_option("--link-tone", args->link.lift_tone,
                  "... and the ground it crosses wants at least this share of the pen's ink at its ends")
      ->capture_default_str()->group("Strokes");
  cmd->add_option("--preview-style", args->preview_style,
                  "pen: the plan drawn with the pens' real widths, ink multiplying (what the plotter draws); "
                  "paper: every mark, lightened, colours averaged where strokes overlap, as in the paper; "
                  "plot: paper's renderer with only the plotted marks")
      ->capture_default_str()->group("Output");
  cmd->add_flag("--measure", args->measure, "Report the mean CIEDE2000 between the blurred preview and the blurred input")
      ->group("Output");
  cmd->add_option("--blur-cells", args->blur_cells, "--measure: Gaussian blur sigma in sampling cells")
      ->capture_default_str()->group("Output");
  m->define(
      [args, space_opt] {
        args->space_given = space_opt->count() > 0;
        resolve(*args);
      },
      [args](const MethodInput& in) {
        auto result = std::make_shared<std::shared_ptr<const sketch::SketchResult>>();
        MethodDraft d = thinned_density(in, [args, &in, result] { return draw(*args, in, result.get()); });
        if (!args->separate) link_scribbles(*args, in, *result, d);
        return args->ground == "none" ? d : ground_beneath(*args, in, **result, d);
      });
}

}  // namespace stipplot::cli
