// stipplot stipple: grayscale-order Poisson disk stippling (seed 000).
#include <memory>

#include "cli/commands.hpp"
#include "cli/method_command.hpp"
#include "methods/stipple/stipple.hpp"
#include "util/progress.hpp"

namespace stipplot::cli {

namespace {
struct StippleArgs {
  std::string method = "gray";
  StippleParams p;
};
}  // namespace

void register_stipple(CLI::App& app) {
  auto args = std::make_shared<StippleArgs>();
  auto m = MethodCommand::add(
      app, "stipple", "Stipple an image with grayscale-order Poisson disk sampling",
      "Methods: gray (dark pixels first; the paper's method), random (random order, for comparison),\n"
      "negative (white dots on black), binary (black and white dots on grey paper),\n"
      "color (binary per R, G, B: the paper's 27-colour screen result), cmyk (ink separation for plotting).\n"
      "Example: stipplot stipple photo.jpg -o photo.svg --preview photo.png --method gray -a 3 -b 15");
  CLI::App* cmd = m->cli();
  const char* g = "Stippling";
  cmd->add_option("-m,--method", args->method, "random|gray|negative|binary|color|cmyk")->capture_default_str();
  cmd->add_option("-a", args->p.a, "Radius offset a in pixels: r = a + b*d/255")->capture_default_str()->group(g);
  cmd->add_option("-b", args->p.b, "Radius slope b in pixels")->capture_default_str()->group(g);
  cmd->add_option("--a-b", args->p.a_b, "Binary/colour: black dot radius offset")->capture_default_str()->group(g);
  cmd->add_option("--b-b", args->p.b_b, "Binary/colour: black dot radius slope")->capture_default_str()->group(g);
  cmd->add_option("--a-w", args->p.a_w, "Binary/colour: white dot radius offset")->capture_default_str()->group(g);
  cmd->add_option("--b-w", args->p.b_w, "Binary/colour: white dot radius slope")->capture_default_str()->group(g);
  cmd->add_option("--seed", args->p.seed, "Random seed; the same seed gives the same drawing")->capture_default_str()->group(g);
  m->define(
      [args] {
        args->p.method = parse_stipple_method(args->method);
        args->p.validate();
      },
      [args](const MethodInput& in) { return fixed_density([args, &in] {
        const StippleParams& p = args->p;
        // A bar only where it helps: big images on a terminal.
        Progress bar("stippling", 1000, in.image.pixels() >= 4'000'000 && in.show_progress);
        MethodResult r;
        r.drawing = stipple(in.image, p, in.placement, [&](double f) { bar.update(static_cast<uint64_t>(f * 1000)); });
        bar.finish();
        r.summary["method"] = to_string(p.method);
        r.counts = std::to_string(r.drawing.primitive_count()) + " dots in " + layers_phrase(r.drawing.layers.size()) +
                   " (" + to_string(p.method) + ", " + pixel_size(in.image) + ")";
        return r;
      }); });
}

}  // namespace stipplot::cli
