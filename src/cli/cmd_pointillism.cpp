// stipplot pointillism: neo-impressionist pointillism with complementary colours (seed 004).
#include <algorithm>
#include <cmath>
#include <memory>

#include "budget/mark_costs.hpp"
#include "cli/commands.hpp"
#include "cli/method_command.hpp"
#include "cli/pen_choice.hpp"
#include "eval/color_difference.hpp"
#include "methods/palette.hpp"
#include "methods/pointillism/pens.hpp"
#include "methods/pointillism/pointillism.hpp"
#include "methods/working_grid.hpp"
#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::cli {

namespace {
struct PointillismArgs {
  pointillism::Params p;
  std::string radius = "3";
  bool no_ebauche = false, no_strokes = false;
  std::string pens_file;
  std::string ebauche = "hatch";  // with pens: hatch | circles
  bool plot_pens = false;
  bool fidelity = false;
  double fidelity_sigma = 0;
  int max_pens = -1;  // not given
  Length radius_length;
  std::vector<Pen> pens;
};

// Options to parameters, before any work. A radius on paper is known in pixels only
// once the image is placed (see draw).
void resolve(PointillismArgs& a) {
  a.p.ebauche = !a.no_ebauche;
  a.p.strokes = !a.no_strokes;
  // A bare number is pixels here (the paper's r = 3 px); a paper unit asks for a size on paper.
  a.radius_length = Length::parse(a.radius, "--radius", Length::Bare::px);
  if (!(a.radius_length.value > 0)) throw UserError("--radius must be > 0, got '" + a.radius + "'");
  require_range("--fidelity-sigma (input px)", a.fidelity_sigma, 0, 1000);
  if (a.radius_length.in_px) {
    a.p.radius_px = a.radius_length.value;
    a.p.validate();
  }
  a.pens.clear();
  if (!a.pens_file.empty()) a.pens = load_palette(a.pens_file, pointillism::kDefaultPenWidthMm).pens;
  else if (a.plot_pens) a.pens = pointillism::default_pens();
  check_max_pens(a.max_pens, a.pens.size(), a.pens_file.empty() ? "the built-in palette" : a.pens_file);
  if (a.ebauche != "hatch" && a.ebauche != "circles")
    throw UserError("--ebauche: unknown style '" + a.ebauche + "' (use hatch or circles)");
}

// The ebauche is hatched where there are pens to lay it (exact colours stay circles).
bool hatched(const PointillismArgs& a) { return !a.pens.empty() && a.p.ebauche && a.ebauche == "hatch"; }

nlohmann::json regions_summary(const pointillism::Result& res) {
  nlohmann::json regions = nlohmann::json::array();
  auto round1 = [](double v) { return std::round(v * 10) / 10; };
  for (const auto& g : res.regions) {
    if (g.pixels == 0) continue;
    regions.push_back({{"L", round1(g.L)},
                       {"a", round1(g.mean.a)},
                       {"b", round1(g.mean.b)},
                       {"circle", round1(g.circle)},
                       {"grey", g.grey},
                       {"n", g.n},
                       {"n_pure", g.n_pure},
                       {"n_complement", g.n_complement}});
  }
  return regions;
}

// The painting (pixel space, once) and the pens it is placed with: `at(k)` lays it at the
// density k (the hatched ebauche's lines 1/k as far apart, the share k of the dots).
struct Painted {
  std::shared_ptr<pointillism::Result> res;
  Placement placement;
  std::vector<Pen> pens;
  bool hatch = false;
  MethodResult base;  // everything but the drawing
  // The budget's knob k: the ebauche's lines 1/k as far apart, the share k^3 of the dots,
  // so the hour goes to the colour fields first (a dot is a pen lift for a speck of ink).
  static double stroke_share(double k) { return k * k * k; }
  Drawing drawing(double coverage, double share) const {
    pointillism::PlaceOptions o;
    o.hatch_ebauche = hatch;
    o.coverage = hatch ? coverage : 1;
    o.stroke_share = hatch ? share : 1;
    return pointillism::place(*res, placement, pens, o);
  }
  MethodResult at(double k) const {
    MethodResult out = base;
    out.drawing = drawing(k, stroke_share(k));
    out.counts += " in " + layers_phrase(out.drawing.layers.size());
    if (hatch) out.summary["ebauche_coverage"] = k;
    return out;
  }
};

Painted paint_once(PointillismArgs& a, const MethodInput& given) {
  // On a grid of one pen width a cell: the same page and pen give the same painting
  // whatever the file's resolution (--radius in px and --blur are in its cells).
  const PageTransform input_tf = given.placement.transform(given.image.width, given.image.height);
  const WorkingGrid grid = make_working_grid(given.image, input_tf, given.placement.pen_width_mm);
  const MethodInput in{grid.image, given.placement, given.costs, given.show_progress};
  if (!a.radius_length.in_px) {
    a.p.radius_px = a.radius_length.value / grid.cell_mm;
    a.p.validate();
  }
  auto res = std::make_shared<pointillism::Result>(pointillism::paint(in.image, a.p));
  MethodResult out;
  std::vector<Pen> draw_pens = a.pens;
  PenChoice choice;
  if (a.max_pens > 0) {
    // The circles do not depend on the pens: paint the small copy once, place it per set.
    const SearchInput search = reduced_input(in, greedy_pen_evaluations(a.pens.size(), static_cast<size_t>(a.max_pens)));
    const pointillism::Result small = pointillism::paint(search.image, a.p);
    pointillism::PlaceOptions po;
    po.hatch_ebauche = hatched(a);  // judged as it will be drawn (at the full tone)
    choice = choose_pens(a.pens, static_cast<size_t>(a.max_pens), search,
                         [&](const std::vector<Pen>& set) { return pointillism::place(small, search.placement, set, po); });
    draw_pens = choice.pens;
  }
  const bool pens = !a.pens.empty();
  nlohmann::json& s = out.summary;
  s["radius_px"] = a.p.radius_px;
  s["ebauche_circles"] = res->ebauche.size();
  s["stroke_circles"] = res->strokes.size();
  s["pens"] = pens ? nlohmann::json(draw_pens.size()) : nlohmann::json("exact colours");
  s["regions"] = regions_summary(*res);
  // Exact colours are opaque paint, one dot covering what is under it; pens are
  // translucent ink that darkens what it crosses.
  out.screen_colours = !pens;
  out.images["--regions-png"] = [res] { return pointillism::region_image(*res); };
  if (a.fidelity) {
    // (in input pixels, as the measure sees the photo)
    const double sigma = a.fidelity_sigma > 0 ? a.fidelity_sigma : 2 * a.p.radius_px * grid.cell_mm / input_tf.mm_per_px();
    out.measure = [sigma, pens](MethodRun& run) {
      const double de = mean_delta_e00_blurred(run.input, run.render_over_image(), sigma);
      run.summary["mean_de00"] = de;
      // With pens, also as if the inks were opaque: the palette's error alone, without
      // the darkening of translucent ink where circles overlap.
      if (pens)
        run.summary["mean_de00_opaque"] = mean_delta_e00_blurred(run.input, run.render_over_image(true), sigma);
      run.summary["fidelity_sigma_px"] = sigma;
      run.note("mean dE00", de);
    };
  }
  const bool hatch = hatched(a);
  s["ebauche_style"] = hatch ? "hatch" : "circles";
  out.counts = std::to_string(res->ebauche.size()) + " ebauche " + (hatch ? "circles hatched" : "circles") + " + " +
               std::to_string(res->strokes.size()) + " stroke circles (" + pixel_size(given.image) + " on a " +
               pixel_size(grid.image) + " grid)";
  if (a.max_pens > 0) report_pen_choice(choice, out);
  return Painted{res, in.placement, draw_pens, hatch, std::move(out)};
}
}  // namespace

void register_pointillism(CLI::App& app) {
  auto args = std::make_shared<PointillismArgs>();
  auto m = MethodCommand::add(
      app, "pointillism", "Neo-impressionist pointillism: ebauche + divided strokes in complementary colours",
      "An ebauche of overlapping circles in the input's colours, then per L* region dots of the pure\n"
      "colour and its complement (Sugita & Takahashi). Exact colours by default (SVG/preview for screens);\n"
      "--plot-pens or --pens FILE.toml maps every circle to the nearest pen (CIEDE2000), one layer per pen\n"
      "(its ebauche, then its dots), light pens before dark; --max-pens N draws with the N that fit best.\n"
      "Pens file: [[pen]] name = \"red\"  color = \"#e42a26\"  width = 0.4\n"
      "Example: stipplot pointillism photo.jpg -o photo.svg --preview photo.png --regions 16 --weight 1.2");
  CLI::App* cmd = m->cli();
  auto* g = "Pointillism";
  cmd->add_option("--regions,-m", args->p.regions, "m: number of uniform L* levels (regions)")
      ->capture_default_str()->group(g);
  cmd->add_option("--weight,-W", args->p.weight, "W: weight of the pure colour's dot count (paper: 0.5, 1, 1.4)")
      ->capture_default_str()->group(g);
  cmd->add_option("--radius,-r", args->radius, "Circle radius: grid cells of one pen width (3, 3px; a bare number is cells) or on paper (0.5mm, 0.05cm, ...)")
      ->capture_default_str()->group(g);
  cmd->add_option("--alpha-ebauche", args->p.alpha_ebauche, "Ebauche PDS: reject when d < alpha (r_i + r_j)")
      ->capture_default_str()->group(g);
  cmd->add_option("--alpha-strokes", args->p.alpha_strokes, "Divided strokes PDS alpha")->capture_default_str()->group(g);
  cmd->add_option("--chroma", args->p.chroma, "Radius of the a*b* circle (0 = gamut-safe chroma per region)")
      ->capture_default_str()->group(g);
  cmd->add_option("--grey-chroma", args->p.grey_chroma,
                  "Regions whose mean chroma is below this get no complement (their own colour instead)")
      ->capture_default_str()->group(g);
  cmd->add_option("--blur", args->p.blur_sigma, "Gaussian blur sigma (grid cells) before splitting regions")
      ->capture_default_str()->group(g);
  cmd->add_option("--ebauche-misses", args->p.ebauche_misses,
                  "Ebauche dart throwing stops after this many misses in a row (0 = maximal, no white left)")
      ->capture_default_str()->group(g);
  cmd->add_flag("--no-ebauche", args->no_ebauche, "Divided strokes on white paper only")->group(g);
  cmd->add_flag("--no-strokes", args->no_strokes, "The ebauche alone (Fig. 6b)")->group(g);
  cmd->add_option("--ebauche", args->ebauche,
                  "With pens: hatch (each pen's ebauche circles filled by one linked hatching, few pen lifts; the\n"
                  "budget spaces its lines) or circles (each circle filled on its own, the paper's)")
      ->capture_default_str()->group(g);
  cmd->add_option("--seed", args->p.seed, "Random seed; the same seed gives the same drawing")
      ->capture_default_str()->group(g);
  cmd->add_flag("--plot-pens", args->plot_pens, "Map colours to the built-in fineliner palette, one layer per pen")
      ->group("Pens");
  cmd->add_option("--pens", args->pens_file, "TOML pen palette (implies --plot-pens)")->group("Pens");
  add_max_pens_option(cmd, args->max_pens);
  m->add_png_output("--regions-png", "Also write the region split (Fig. 6c) as a PNG", "regions_png", "");
  cmd->add_flag("--fidelity", args->fidelity,
                "Measure mean CIEDE2000 between blurred preview and blurred input (adds mean_de00)")
      ->group("Output");
  cmd->add_option("--fidelity-sigma", args->fidelity_sigma, "Blur for --fidelity in input px (0 = 2 x radius)")
      ->capture_default_str()->group("Output");
  m->warm_up_beside_decode(pointillism::prepare_colour_tables);
  m->define([args] { resolve(*args); },
            [args](const MethodInput& in) {
              // A hatched ebauche is thinned by spacing its lines, not by leaving out whole ones.
              if (hatched(*args)) {
                auto painted = std::make_shared<Painted>(paint_once(*args, in));
                auto full = std::make_shared<MethodResult>(painted->at(1));  // placed once
                // The ebauche's share of the full drawing's time predicts the rest: k of it,
                // and k^3 of the dots'.
                const budget::MarkCosts& c = in.costs;
                const double all = budget::quick_estimate_seconds(full->drawing, c.motion(), c.plan_options());
                const double eb = budget::quick_estimate_seconds(painted->drawing(1, 0), c.motion(), c.plan_options());
                const double w = all > 0 ? std::clamp(eb / all, 0.0, 1.0) : 1;
                return scaled_density(
                    in, [painted, full](double k) { return k >= 1 ? *full : painted->at(k); },
                    [w](double k) { return w * k + (1 - w) * Painted::stroke_share(k); });
              }
              return thinned_density(in, [args, &in] { return paint_once(*args, in).at(1); });
            });
}

}  // namespace stipplot::cli
