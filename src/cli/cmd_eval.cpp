// stipplot eval: how faithfully a preview reproduces its input.
#include <memory>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "eval/fidelity.hpp"
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
  CLI::App* cmd = app.add_subcommand("eval", "Measure a preview against its input: blurred SSIM and edge spill");
  cmd->footer(
      "Give the same --page/--margin/--landscape the preview was made with, or --cropped if the\n"
      "PNG shows exactly the image area.\n"
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
    if (a.json) {
      nlohmann::json j = {{"ssim_blurred", r.ssim_blurred}, {"sigma", r.sigma},
                          {"dot_spacing", r.dot_spacing},   {"dots", r.dots},
                          {"dark_dots", r.dark_dots},       {"light_dots", r.light_dots},
                          {"dots_near_edges", r.dots_near_edges}, {"spilled", r.spilled},
                          {"edge_spill", r.edge_spill},     {"paper_level", r.paper_level}};
      std::printf("%s\n", j.dump().c_str());
    } else {
      std::printf("blurred SSIM %.4f (sigma %.2f px, dot spacing %.2f px, %zu dots)\n", r.ssim_blurred, r.sigma,
                  r.dot_spacing, r.dots);
      std::printf("edge spill   %.4f (%zu of %zu dots within %.1f px of a strong edge lie on its wrong side)\n",
                  r.edge_spill, r.spilled, r.dots_near_edges, a.opt.edge_distance);
    }
  });
}

}  // namespace stipplot::cli
