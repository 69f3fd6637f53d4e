// stipplot pointillism: neo-impressionist pointillism with complementary colours (seed 004).
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "eval/fidelity.hpp"
#include "methods/pointillism/pens.hpp"
#include "methods/pointillism/pointillism.hpp"
#include "preview/preview.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

namespace {
struct PointillismArgs {
  OutputArgs out;
  PlacementArgs place;
  pointillism::Params p;
  std::string radius = "3";
  bool no_ebauche = false, no_strokes = false;
  std::string pens_file;
  bool plot_pens = false;
  std::string regions_png;
  bool fidelity = false;
  double fidelity_sigma = 0;
};

// Exact colours are opaque paint, one dot covering what is under it; pens are
// translucent ink that darkens what it crosses.
PreviewOptions preview_options(double dpi, bool pens) {
  PreviewOptions po;
  po.dpi = dpi;
  po.ink_multiplies = pens;
  return po;
}
}  // namespace

void register_pointillism(CLI::App& app) {
  auto args = std::make_shared<PointillismArgs>();
  CLI::App* cmd = app.add_subcommand(
      "pointillism", "Neo-impressionist pointillism: ebauche + divided strokes in complementary colours");
  cmd->footer(
      "An ebauche of overlapping circles in the input's colours, then per L* region dots of the pure\n"
      "colour and its complement (Sugita & Takahashi). Exact colours by default (SVG/preview for screens);\n"
      "--plot-pens or --pens FILE.toml maps every circle to the nearest pen (CIEDE2000), one layer per pen.\n"
      "Pens file: [[pen]] name = \"red\"  color = \"#e42a26\"  width = 0.4\n"
      "Example: stipplot pointillism photo.jpg -o photo.svg --preview photo.png --regions 16 --weight 1.2");
  add_output_options(cmd, args->out);
  add_placement_options(cmd, args->place);
  auto* g = "Pointillism";
  cmd->add_option("--regions,-m", args->p.regions, "m: number of uniform L* levels (regions)")
      ->capture_default_str()->group(g);
  cmd->add_option("--weight,-W", args->p.weight, "W: weight of the pure colour's dot count (paper: 0.5, 1, 1.4)")
      ->capture_default_str()->group(g);
  cmd->add_option("--radius,-r", args->radius, "Circle radius: input pixels (3, 3px; a bare number is pixels) or on paper (0.5mm, 0.05cm, ...)")
      ->capture_default_str()->group(g);
  cmd->add_option("--alpha-ebauche", args->p.alpha_ebauche, "Ebauche PDS: reject when d < alpha (r_i + r_j)")
      ->capture_default_str()->group(g);
  cmd->add_option("--alpha-strokes", args->p.alpha_strokes, "Divided strokes PDS alpha")->capture_default_str()->group(g);
  cmd->add_option("--chroma", args->p.chroma, "Radius of the a*b* circle (0 = gamut-safe chroma per region)")
      ->capture_default_str()->group(g);
  cmd->add_option("--grey-chroma", args->p.grey_chroma,
                  "Regions whose mean chroma is below this get no complement (their own colour instead)")
      ->capture_default_str()->group(g);
  cmd->add_option("--blur", args->p.blur_sigma, "Gaussian blur sigma (px) before splitting regions")
      ->capture_default_str()->group(g);
  cmd->add_option("--ebauche-misses", args->p.ebauche_misses,
                  "Ebauche dart throwing stops after this many misses in a row (0 = maximal, no white left)")
      ->capture_default_str()->group(g);
  cmd->add_flag("--no-ebauche", args->no_ebauche, "Divided strokes on white paper only")->group(g);
  cmd->add_flag("--no-strokes", args->no_strokes, "The ebauche alone (Fig. 6b)")->group(g);
  cmd->add_option("--seed", args->p.seed, "Random seed; the same seed gives the same drawing")
      ->capture_default_str()->group(g);
  cmd->add_flag("--plot-pens", args->plot_pens, "Map colours to the built-in fineliner palette, one layer per pen")
      ->group("Pens");
  cmd->add_option("--pens", args->pens_file, "TOML pen palette (implies --plot-pens)")->group("Pens");
  cmd->add_option("--regions-png", args->regions_png, "Also write the region split (Fig. 6c) as a PNG")
      ->group("Output");
  cmd->add_flag("--fidelity", args->fidelity,
                "Measure mean CIEDE2000 between blurred preview and blurred input (adds mean_de00)")
      ->group("Output");
  cmd->add_option("--fidelity-sigma", args->fidelity_sigma, "Blur for --fidelity in input px (0 = 2 x radius)")
      ->capture_default_str()->group("Output");
  cmd->callback([args] {
    auto t0 = std::chrono::steady_clock::now();
    PointillismArgs& a = *args;
    a.p.ebauche = !a.no_ebauche;
    a.p.strokes = !a.no_strokes;
    // A bare number is pixels here (the paper's r = 3 px); a paper unit asks for a size on paper.
    const Length radius = Length::parse(a.radius, "--radius", Length::Bare::px);
    const bool radius_mm = !radius.in_px;
    if (!(radius.value > 0)) throw UserError("--radius must be > 0, got '" + a.radius + "'");
    require_nonnegative("--fidelity-sigma", a.fidelity_sigma);
    if (!radius_mm) {
      a.p.radius_px = radius.value;
      a.p.validate();
    }
    Placement placement = a.place.resolve();
    a.out.validate();
    if (!a.regions_png.empty()) {
      if (a.regions_png.size() < 4 || a.regions_png.substr(a.regions_png.size() - 4) != ".png")
        throw UserError("--regions-png " + a.regions_png + ": expected a .png file");
      require_writable_dir(a.regions_png);
    }
    std::vector<Pen> pens;
    if (!a.pens_file.empty()) pens = pointillism::load_pens(a.pens_file);
    else if (a.plot_pens) pens = pointillism::default_pens();
    if (!a.pens_file.empty() && pens.empty()) throw UserError("--pens " + a.pens_file + ": the palette is empty");
    Image img = load_input(a.out);
    const PageTransform tf = placement.transform(img.width, img.height);
    if (radius_mm) {
      a.p.radius_px = radius.value / tf.mm_per_px();
      a.p.validate();
    }

    auto t1 = std::chrono::steady_clock::now();
    pointillism::Result res = pointillism::paint(img, a.p);
    Drawing d = pointillism::place(res, placement, pens);
    const double method_s = seconds_since(t1);

    nlohmann::json s;
    s["command"] = "pointillism";
    s["input"] = a.out.input;
    s["image_px"] = {img.width, img.height};
    s["radius_px"] = a.p.radius_px;
    s["ebauche_circles"] = res.ebauche.size();
    s["stroke_circles"] = res.strokes.size();
    s["pens"] = pens.empty() ? nlohmann::json("exact colours") : nlohmann::json(pens.size());
    nlohmann::json regions = nlohmann::json::array();
    for (const auto& g : res.regions) {
      if (g.pixels == 0) continue;
      regions.push_back({{"L", std::round(g.L * 10) / 10},
                         {"a", std::round(g.mean.a * 10) / 10},
                         {"b", std::round(g.mean.b * 10) / 10},
                         {"circle", std::round(g.circle * 10) / 10},
                         {"grey", g.grey},
                         {"n", g.n},
                         {"n_pure", g.n_pure},
                         {"n_complement", g.n_complement}});
    }
    s["regions"] = regions;

    OutputArgs svg_only = a.out;
    svg_only.preview.clear();
    write_outputs(d, svg_only, s);
    if (!a.out.preview.empty()) {
      write_preview_png(d, a.out.preview, preview_options(a.out.preview_dpi, !pens.empty()));
      s["preview"] = a.out.preview;
    }
    if (!a.regions_png.empty()) {
      write_png(pointillism::region_image(res), a.regions_png);
      s["regions_png"] = a.regions_png;
    }
    if (a.fidelity) {
      // One preview pixel per input pixel, then the image's rectangle cut out.
      const double dpi = std::clamp(25.4 / tf.mm_per_px(), 10.0, 2400.0);
      const double sigma = a.fidelity_sigma > 0 ? a.fidelity_sigma : 2 * a.p.radius_px;
      auto measure = [&](bool ink_multiplies) {
        Image page = render_preview(d, preview_options(dpi, ink_multiplies));
        Image drawn = crop_to_image(page, tf, img.width, img.height);
        return pointillism::mean_delta_e00_blurred(img, drawn, sigma);
      };
      s["mean_de00"] = measure(!pens.empty());
      // With pens, also as if the inks were opaque: the palette's error alone, without
      // the darkening of translucent ink where circles overlap.
      if (!pens.empty()) s["mean_de00_opaque"] = measure(false);
      s["fidelity_sigma_px"] = sigma;
    }
    s["seconds_method"] = method_s;
    s["seconds"] = seconds_since(t0);
    std::ostringstream h;
    h.setf(std::ios::fixed);
    h.precision(2);
    h << "wrote " << a.out.output << ": " << res.ebauche.size() << " ebauche + " << res.strokes.size()
      << " stroke circles in " << d.layers.size() << (d.layers.size() == 1 ? " layer" : " layers") << " ("
      << img.width << "x" << img.height << " px) in " << s["seconds"].get<double>() << " s";
    if (a.fidelity) h << "; mean dE00 " << s["mean_de00"].get<double>();
    if (!a.out.preview.empty()) h << "; preview " << a.out.preview;
    report(a.out, s, h.str());
  });
}

}  // namespace stipplot::cli
