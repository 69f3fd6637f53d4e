// stipplot stipple: grayscale-order Poisson disk stippling (seed 000).
#include <memory>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "methods/stipple/stipple.hpp"
#include "util/progress.hpp"

namespace stipplot::cli {

namespace {
struct StippleArgs {
  OutputArgs out;
  PlacementArgs place;
  std::string method = "gray";
  StippleParams p;
};
}  // namespace

void register_stipple(CLI::App& app) {
  auto args = std::make_shared<StippleArgs>();
  CLI::App* cmd = app.add_subcommand("stipple", "Stipple an image with grayscale-order Poisson disk sampling");
  cmd->footer(
      "Methods: gray (dark pixels first; the paper's method), random (random order, for comparison),\n"
      "negative (white dots on black), binary (black and white dots on grey paper),\n"
      "color (binary per R, G, B: the paper's 27-colour screen result), cmyk (ink separation for plotting).\n"
      "Example: stipplot stipple photo.jpg -o photo.svg --preview photo.png --method gray -a 3 -b 15");
  add_output_options(cmd, args->out);
  add_placement_options(cmd, args->place);
  cmd->add_option("-m,--method", args->method, "random|gray|negative|binary|color|cmyk")->capture_default_str();
  cmd->add_option("-a", args->p.a, "Radius offset a in pixels: r = a + b*d/255")->capture_default_str()->group("Stippling");
  cmd->add_option("-b", args->p.b, "Radius slope b in pixels")->capture_default_str()->group("Stippling");
  cmd->add_option("--a-b", args->p.a_b, "Binary/colour: black dot radius offset")->capture_default_str()->group("Stippling");
  cmd->add_option("--b-b", args->p.b_b, "Binary/colour: black dot radius slope")->capture_default_str()->group("Stippling");
  cmd->add_option("--a-w", args->p.a_w, "Binary/colour: white dot radius offset")->capture_default_str()->group("Stippling");
  cmd->add_option("--b-w", args->p.b_w, "Binary/colour: white dot radius slope")->capture_default_str()->group("Stippling");
  cmd->add_option("--seed", args->p.seed, "Random seed; the same seed gives the same drawing")->capture_default_str()->group("Stippling");
  cmd->callback([args] {
    auto t0 = std::chrono::steady_clock::now();
    StippleArgs& a = *args;
    a.p.method = parse_stipple_method(a.method);
    a.p.validate();
    Placement placement = a.place.resolve();
    a.out.validate();
    Image img = load_input(a.out);
    auto t1 = std::chrono::steady_clock::now();
    // A bar only where it helps: big images on a terminal, never with --json/--quiet.
    Progress bar("stippling", 1000, img.pixels() >= 4'000'000 && !a.out.json && !a.out.quiet);
    Drawing d = stipple(img, a.p, placement, [&](double f) { bar.update(static_cast<uint64_t>(f * 1000)); });
    bar.finish();
    double method_s = seconds_since(t1);
    nlohmann::json s;
    s["command"] = "stipple";
    s["method"] = to_string(a.p.method);
    s["input"] = a.out.input;
    s["image_px"] = {img.width, img.height};
    write_outputs(d, a.out, s);
    s["seconds_method"] = method_s;
    s["seconds"] = seconds_since(t0);
    std::ostringstream h;
    h << "wrote " << a.out.output << ": " << s["primitives"].get<size_t>() << " dots in " << d.layers.size()
      << (d.layers.size() == 1 ? " layer" : " layers") << " (" << to_string(a.p.method) << ", "
      << img.width << "x" << img.height << " px) in " << std::fixed;
    h.precision(2);
    h << s["seconds"].get<double>() << " s";
    if (!a.out.preview.empty()) h << "; preview " << a.out.preview;
    report(a.out, s, h.str());
  });
}

}  // namespace stipplot::cli
