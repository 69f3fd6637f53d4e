// stipplot eval: how faithfully a drawing (an SVG, or a preview PNG) reproduces its input.
#include <memory>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "eval/color_difference.hpp"
#include "eval/fidelity.hpp"
#include "eval/tone.hpp"
#include "eval/view.hpp"
#include "plan/planner.hpp"
#include "preview/preview.hpp"
#include "svg/svg_reader.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

namespace {

struct EvalArgs {
  std::string input, drawing;
  PlacementArgs place;
  CLI::Option* page_option = nullptr;
  FidelityOptions opt;
  std::string view_sigma = "1mm";
  std::string profile = "grbl-servo";
  bool json = false;
  bool cropped = false;
  bool view_only = false;
  bool no_colour = false;
};

// The drawing as a whole page, and how the input lies on it. An SVG is planned for the
// profile and rendered pen-true at measure.py's 10 px/mm (fewer on pages over 25 MP), on
// its own page unless --page is given; a PNG is a page preview, or with --cropped the
// image's rectangle alone (then a page of that rectangle, no margin).
struct PageDrawing {
  Image page;
  PageTransform tf;
};

PageDrawing drawing_page(const EvalArgs& a, const Image& in) {
  Placement pl = a.place.resolve();
  if (has_extension(a.drawing, ".svg")) {
    const Drawing d = read_svg(a.drawing);
    if (!a.page_option || a.page_option->count() == 0) {
      pl.page = {d.page.width_mm, d.page.height_mm};
      pl.landscape = false;
    }
    const DeviceProfile prof = find_profile(a.profile);
    const Plan plan = plan_drawing(d, plan_options_for(prof, d.page, PlanArgs{}));
    PreviewOptions po;
    po.dpi = 25.4 * view_px_per_mm(d.page.width_mm, d.page.height_mm);
    return {render_plan(plan, po), pl.transform(in.width, in.height)};
  }
  Image pv = load_image(a.drawing);
  if (!a.cropped) return {std::move(pv), pl.transform(in.width, in.height)};
  const PageTransform on_page = pl.transform(in.width, in.height);
  const PageSpec rect{in.width * on_page.mm_per_px(), in.height * on_page.mm_per_px()};
  return {std::move(pv), PageTransform(in.width, in.height, rect, 0, false)};
}

void print_view(const ViewScore& v) {
  std::printf("viewed at    sigma %.2f mm: SSIM %.3f, tone r %.3f, tone error %.3f (mean grey %.3f drawn, %.3f photo)",
              v.sigma_mm, v.ssim, v.tone_r, v.tone_err, v.mean_drawn, v.mean_photo);
  if (v.delta_e >= 0) std::printf(", mean dE00 %.2f", v.delta_e);
  std::printf("\n");
}

void print_text(const ViewScore& v, const ToneFit& tone, double de, const FidelityResult& r, double tone_sigma,
                double edge_distance) {
  print_view(v);
  std::printf("at the marks' spacing (%.2f px):\n", tone_sigma);
  std::printf("tone         slope %.3f, r %.3f (mean grey %.3f drawn, %.3f input)\n", tone.slope, tone.pearson,
              tone.mean_drawn, tone.mean_input);
  std::printf("colour       mean dE00 %.2f\n", de);
  std::printf("blurred SSIM %.4f (sigma %.2f px, dot spacing %.2f px, %zu dots)\n", r.ssim_blurred, r.sigma,
              r.dot_spacing, r.dots);
  std::printf("edge spill   %.4f (%zu of %zu dots within %.1f px of a strong edge lie on its wrong side)\n",
              r.edge_spill, r.spilled, r.dots_near_edges, edge_distance);
}

}  // namespace

void register_eval(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = app.add_subcommand("eval", "Measure a drawing against its input: viewed from a distance, tone, colour, edge spill");
  cmd->footer(
      "DRAWING is the SVG a method wrote (planned for --profile and rendered as the pens draw it) or a\n"
      "preview PNG. First figures: both blurred by --view-sigma on paper (the eye at a viewing\n"
      "distance, whatever the marks), then SSIM, tone correlation r, tone error and mean CIEDE2000.\n"
      "Then the older figures, blurred at the mark spacing (or --sigma): tone fit (slope 1 = the\n"
      "photo's tones), colour, blurred SSIM and edge spill. Give the same --margin/--landscape the\n"
      "drawing was made with (an SVG brings its page), or --cropped if the PNG shows exactly the image.\n"
      "Example: stipplot eval photo.jpg photo.svg --view-sigma 0.5mm --json\n"
      "         stipplot eval photo.jpg preview.png --view-only   (the viewing-distance figures alone)");
  cmd->add_option("input", args->input, "The input image")->required();
  cmd->add_option("drawing", args->drawing, "The drawing: SVG (stipplot METHOD -o) or preview PNG (--preview)")->required();
  add_placement_options(cmd, args->place);
  args->page_option = cmd->get_option("--page");
  cmd->add_flag("--cropped", args->cropped, "The preview covers exactly the image (no page around it)");
  cmd->add_option("--view-sigma", args->view_sigma, "Viewing-distance blur on paper, with its unit (1mm, 0.5mm)")
      ->capture_default_str();
  cmd->add_option("--profile", args->profile, "Device profile an SVG is planned for")->capture_default_str();
  cmd->add_option("--sigma", args->opt.sigma, "Blur of the older figures in input pixels (0 = the measured dot spacing)")
      ->capture_default_str();
  cmd->add_option("--edge-distance", args->opt.edge_distance, "Distance in px from an edge that counts as near")
      ->capture_default_str();
  cmd->add_flag("--view-only", args->view_only,
                "Only the viewing-distance figures: the older ones at the mark spacing take seconds more on a large photo");
  cmd->add_flag("--no-colour", args->no_colour,
                "With --view-only: leave out the mean dE00 (a CIEDE2000 a pixel: a second of a 12-MP photo on A3)");
  cmd->add_flag("--json", args->json, "One-line JSON output");
  cmd->callback([args] {
    EvalArgs& a = *args;
    ViewOptions vo;
    vo.sigma_mm = parse_view_sigma_mm(a.view_sigma);
    if (a.no_colour && !a.view_only) throw UserError("--no-colour goes with --view-only (the other figures include colour)");
    vo.colour = !a.no_colour;
    require_range("--sigma (input px)", a.opt.sigma, 0, 1000);
    require_range("--edge-distance (input px)", a.opt.edge_distance, 0, 100000);
    if (a.cropped && has_extension(a.drawing, ".svg")) throw UserError("--cropped is for a preview PNG, not an SVG");
    const Image in = load_image(a.input);
    const PageDrawing pd = drawing_page(a, in);
    const ViewScore v = view_score(in, pd.tf, pd.page, vo);
    nlohmann::json j = {{"view_sigma_mm", v.sigma_mm}, {"ssim_view", v.ssim}, {"tone_r_view", v.tone_r},
                        {"tone_err_view", v.tone_err}, {"delta_e_view", v.delta_e},
                        {"mean_grey_drawn_view", v.mean_drawn}, {"mean_grey_photo_view", v.mean_photo},
                        {"view_px_per_mm", v.px_per_mm}};
    if (!vo.colour) j.erase("delta_e_view");
    if (a.view_only) {
      if (a.json) std::printf("%s\n", j.dump().c_str());
      else print_view(v);
      return;
    }
    const Image drawn = a.cropped ? pd.page : crop_to_image(pd.page, pd.tf, in.width, in.height);
    const FidelityResult r = evaluate_fidelity(in, drawn, a.opt);
    // The older tone and colour figures are seen where the marks merge: at their spacing.
    const double tone_sigma = a.opt.sigma > 0 ? a.opt.sigma : (r.mark_spacing > 0 ? r.mark_spacing : r.sigma);
    const ToneFit tone = fit_tone(in, drawn, tone_sigma);
    const double de = mean_delta_e00_blurred(in, drawn, tone_sigma);
    if (!a.json) return print_text(v, tone, de, r, tone_sigma, a.opt.edge_distance);
    j.update(nlohmann::json{{"tone_slope", tone.slope}, {"tone_intercept", tone.intercept},
                        {"tone_r", tone.pearson}, {"mean_grey_input", tone.mean_input},
                        {"mean_grey_drawn", tone.mean_drawn}, {"mean_de00", de},
                        {"mark_spacing", r.mark_spacing}, {"tone_sigma", tone_sigma},
                        {"ssim_blurred", r.ssim_blurred}, {"sigma", r.sigma},
                        {"dot_spacing", r.dot_spacing},   {"dots", r.dots},
                        {"dark_dots", r.dark_dots},       {"light_dots", r.light_dots},
                        {"dots_near_edges", r.dots_near_edges}, {"spilled", r.spilled},
                        {"edge_spill", r.edge_spill},     {"paper_level", r.paper_level}});
    std::printf("%s\n", j.dump().c_str());
  });
}

}  // namespace stipplot::cli
