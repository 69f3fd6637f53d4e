// stipplot eval: how faithfully a preview reproduces its input.
#include <memory>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "eval/color_difference.hpp"
#include "eval/fidelity.hpp"
#include "eval/tone.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

void register_eval(CLI::App& app) {
  struct Args {
    std::string input, preview;
    PlacementArgs place;
    FidelityOptions opt;
    bool json = false;
    bool cropped = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("eval", "Measure a preview against its input: tone, colour, blurred SSIM, edge spill");
  cmd->footer(
      "Give the same --page/--margin/--landscape the preview was made with, or --cropped if the\n"
      "PNG shows exactly the image area. Both images are blurred at the mark spacing (or --sigma);\n"
      "tone: the drawing's grey fitted against the input's (slope 1 = the photo's tones), colour:\n"
      "mean CIEDE2000.\n"
      "Example: stipplot eval photo.jpg photo-preview.png --json");
  cmd->add_option("input", args->input, "The input image")->required();
  cmd->add_option("preview", args->preview, "The preview PNG (stipplot ... --preview)")->required();
  add_placement_options(cmd, args->place);
  cmd->add_flag("--cropped", args->cropped, "The preview covers exactly the image (no page around it)");
  cmd->add_option("--sigma", args->opt.sigma, "Blur in input pixels (0 = the measured dot spacing)")->capture_default_str();
  cmd->add_option("--edge-distance", args->opt.edge_distance, "Distance in px from an edge that counts as near")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "One-line JSON output");
  cmd->callback([args] {
    Args& a = *args;
    Placement pl = a.place.resolve();
    require_range("--sigma (input px)", a.opt.sigma, 0, 1000);
    require_range("--edge-distance (input px)", a.opt.edge_distance, 0, 100000);
    Image in = load_image(a.input);
    Image pv = load_image(a.preview);
    Image drawn = a.cropped ? pv : crop_to_image(pv, pl.transform(in.width, in.height), in.width, in.height);
    FidelityResult r = evaluate_fidelity(in, drawn, a.opt);
    // Tone and colour are seen where the marks merge: at the marks' spacing.
    const double tone_sigma = a.opt.sigma > 0 ? a.opt.sigma : (r.mark_spacing > 0 ? r.mark_spacing : r.sigma);
    const ToneFit tone = fit_tone(in, drawn, tone_sigma);
    const double de = mean_delta_e00_blurred(in, drawn, tone_sigma);
    if (a.json) {
      nlohmann::json j = {{"tone_slope", tone.slope}, {"tone_intercept", tone.intercept},
                          {"tone_r", tone.pearson}, {"mean_grey_input", tone.mean_input},
                          {"mean_grey_drawn", tone.mean_drawn}, {"mean_de00", de},
                          {"mark_spacing", r.mark_spacing}, {"tone_sigma", tone_sigma},
                          {"ssim_blurred", r.ssim_blurred}, {"sigma", r.sigma},
                          {"dot_spacing", r.dot_spacing},   {"dots", r.dots},
                          {"dark_dots", r.dark_dots},       {"light_dots", r.light_dots},
                          {"dots_near_edges", r.dots_near_edges}, {"spilled", r.spilled},
                          {"edge_spill", r.edge_spill},     {"paper_level", r.paper_level}};
      std::printf("%s\n", j.dump().c_str());
    } else {
      std::printf("tone         slope %.3f, r %.3f (mean grey %.3f drawn, %.3f input; blur %.2f px)\n", tone.slope,
                  tone.pearson, tone.mean_drawn, tone.mean_input, tone_sigma);
      std::printf("colour       mean dE00 %.2f\n", de);
      std::printf("blurred SSIM %.4f (sigma %.2f px, dot spacing %.2f px, %zu dots)\n", r.ssim_blurred, r.sigma,
                  r.dot_spacing, r.dots);
      std::printf("edge spill   %.4f (%zu of %zu dots within %.1f px of a strong edge lie on its wrong side)\n",
                  r.edge_spill, r.spilled, r.dots_near_edges, a.opt.edge_distance);
    }
  });
}

}  // namespace stipplot::cli
