#pragma once
// The one command line every drawing method goes through (stipple, tree, sketch,
// pointillism), after vpype's `generator` decorator: the options all methods share are
// added once, and the one path from a method's Drawing to its outputs is written once:
// check every option and output before any work, load the image, run the method, then
// -o (SVG, or planned G-code/HPGL), the preview PNG, the method's extra PNGs, its
// measurements, the --json line and the "wrote ..." sentence. Every drawing is made for
// a plot-time budget (--time, default 1 h on --profile): the method says how its plot
// time grows with one density knob, and the shared search (budget/density_search.hpp)
// picks the knob. A cmd_*.cpp adds only its own options and turns an image into a
// MethodDraft; anything to do to every method's drawing on its way to the outputs
// belongs in MethodCommand::run.
#include <CLI/CLI.hpp>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "budget/mark_costs.hpp"
#include "cli/common.hpp"
#include "geometry/drawing.hpp"
#include "geometry/page.hpp"
#include "image/image.hpp"
#include "methods/placement.hpp"
#include "plan/plan.hpp"

namespace stipplot::cli {

class MethodRun;

// What a method is given.
struct MethodInput {
  const Image& image;
  const Placement& placement;
  const budget::MarkCosts& costs;  // what marks cost on the chosen profile
  bool show_progress = false;      // a progress bar is welcome (no --json, no --quiet)
  double budget_s = 0;             // the --time budget in seconds (0: not known, a search's small copy)
  // --draft: working grids on the page no finer than this (mm; 0: full resolution). The
  // preview's pixel: finer cells would not show.
  double draft_cell_mm = 0;
};

// What a method hands to the shared output path.
struct MethodResult {
  Drawing drawing;
  nlohmann::json summary = nlohmann::json::object();  // the method's own --json fields
  // The sentence's middle: "wrote OUT: <counts> in 1.23 s", e.g. "1234 dots in 1 layer
  // (gray, 640x480 px)".
  std::string counts;
  // The preview and the measures are the pen-true render of the plan (preview.hpp) ...
  // unless the drawing is in screen colours no pen has (pointillism's exact colours,
  // stipple's 26 colours): then its primitives are painted as they are, opaque ...
  bool screen_colours = false;
  // ... or the method renders its marks itself (the sketch's paper-style preview, which
  // averages overlapping colours); called at most once, at --preview-dpi.
  std::function<Image(double dpi)> render_preview;
  // The images of the method's extra PNG options, by option name ("--terrain"); each is
  // made only when its option was given.
  std::map<std::string, std::function<Image()>> images;
  // Measurements once every file is written (see MethodRun).
  std::function<void(MethodRun&)> measure;
};

// A method ready to draw at any density: what the budget search needs (see
// budget/density_search.hpp). The knob k is in [0, 1]; plot time grows with it; 1 is the
// finest drawing the method makes.
struct MethodDraft {
  std::function<double(double k)> predict;     // plot seconds at k, cheap (statistics x mark costs)
  std::function<MethodResult(double k)> draw;  // the method at k
  std::function<void(double k)> calibrate;     // optional: a cheap pilot at k that corrects predict
  // The share of the photo's tone the drawing at k reaches (1 = all of it: the budget
  // fades the drawing evenly below that). Null: always all of it.
  std::function<double(double k)> tone_share;
  double ink_needed = 0;  // mean ink coverage of the page area the photo's tones need
};

// A method whose drawing does not depend on the budget: one run, whatever --time says.
MethodDraft fixed_density(std::function<MethodResult()> draw);

// A method whose marks cannot be thinned one by one (a tree: each point holds others up),
// but whose spacing can grow: at k the method runs with its spacing x 1/sqrt(k), so it
// makes about k of its marks and takes about k of the time. Costs one run at full density
// and its quick estimate, then one run at each density the search tries.
MethodDraft spaced_density(const MethodInput& in, std::function<MethodResult(double spacing)> draw);

// A method whose marks each lay a little of the tone (sketch strokes, pointillism
// circles): one run at its full density, then at k < 1 each layer keeps the share k of
// its marks, picked by a golden-ratio sequence over their order so the thinning is even
// and the tone fades evenly. The plot time of the full run, scaled by k, predicts the
// rest. Costs one run of the method, its quick estimate, and O(marks) a thinning.
MethodDraft thinned_density(const MethodInput& in, std::function<MethodResult()> draw);

// A method that scales its own density: draw(k) lays about the share k of its full
// drawing's ink and time (pointillism's hatched ebauche: its lines 1/k as far apart, and
// the share k of its dots). The full run's plot time scaled by k predicts the rest. Costs
// one full run and its quick estimate, then one draw(k) a density the search tries.
// `time_share(k)`, if given, is the share of the full run's time the drawing at k takes
// (default k).
MethodDraft scaled_density(const MethodInput& in, std::function<MethodResult(double k)> draw,
                           std::function<double(double k)> time_share = {});

// The drawing with the share k of every layer's marks of each kind (see thinned_density).
Drawing thin_marks(const Drawing& d, double k);

// What a method's measurement sees and adds to.
class MethodRun {
 public:
  MethodRun(const Image& input, const PageTransform& transform, const MethodResult& result, const Plan& plan,
            double preview_dpi, nlohmann::json& summary);
  const Image& input;
  const PageTransform& transform;  // how the image lies on the page
  const MethodResult& result;
  const Plan& plan;                // what the plotter will draw
  nlohmann::json& summary;
  // Appends "; <label> <value>" (two decimals) to the sentence, before the preview is
  // named: "; mean dE00 4.20".
  void note(const std::string& label, double value);
  const std::string& notes() const { return notes_; }
  // The preview (rendered once, at --preview-dpi) cut to the image's rectangle.
  Image preview_over_image();
  // The preview as a whole page, rendered once; written to --preview by MethodCommand.
  const Image& preview_page();
  // Renders the preview on a thread of its own, while the caller writes the other
  // outputs; preview_page() waits for it. Call before anything else reads the preview.
  void render_preview_beside();
  // The pen-true render (or the screen-colour paint, see MethodResult) at one pixel per
  // input pixel (at least 150 dpi), cut to the image's rectangle: what a measure compares
  // with the input. `opaque`: every pen's ink painted over what is under it instead.
  Image render_over_image(bool opaque = false) const;
  // The same as a whole page at `px_per_mm`: what the viewing-distance measure compares.
  Image render_page(double px_per_mm) const;

 private:
  Image render_preview_page() const;
  double preview_dpi_;
  std::string notes_;
  std::unique_ptr<Image> preview_;
  std::future<void> rendering_;
};

// "640x480 px", as the sentences give an image's size.
std::string pixel_size(const Image& image);

class MethodCommand {
 public:
  // Adds subcommand `name` with the shared options: IN, -o, --profile and planning,
  // --time, --preview, --preview-dpi, --json, --quiet, --max-pixels, and the page options.
  static std::shared_ptr<MethodCommand> add(CLI::App& app, const std::string& name, const std::string& description,
                                            const std::string& footer);
  CLI::App* cli() const { return cmd_; }

  // An extra PNG the method can write: checked (.png, directory exists) with -o before
  // any work, filled from MethodResult::images, reported under `json_key`, and named in
  // the sentence after the preview as "; <sentence_word> PATH" unless the word is empty.
  void add_png_output(const std::string& option, const std::string& help, const std::string& json_key,
                      const std::string& sentence_word);

  // The method: `check` turns its options into parameters before any file is read or
  // written (throws UserError); `prepare` readies it for the image (working grid,
  // statistics) and returns how to draw it at any density. A method without a --measure
  // or --fidelity of its own is given a --measure here: every method's measure reports the
  // viewing-distance figures (eval/view.hpp) at --view-sigma.
  void define(std::function<void()> check, std::function<MethodDraft(const MethodInput&)> prepare);
  // Work the method needs later that does not need the photo (OpenCV's Lab tables, built
  // once a process in soft-float: 60 ms), run on a second thread while the photo decodes,
  // which is serial. Nothing with one thread: it then runs where it is first needed.
  void warm_up_beside_decode(std::function<void()> work) { warm_up_ = std::move(work); }

 private:
  MethodCommand() = default;
  void run() const;
  void check_outputs() const;
  // `laid_out` is the drawing for -o laid out for the device (null: r.drawing itself).
  void write_outputs(MethodResult& r, const Drawing* laid_out, MethodRun& run, nlohmann::json& s) const;
  std::string sentence(const MethodResult& r, const MethodRun& run, const nlohmann::json& s,
                       const std::string& budget_words) const;

  struct Args;
  struct PngOutput {
    std::string option, json_key, sentence_word, path;
  };
  CLI::App* cmd_ = nullptr;
  std::string name_;
  std::shared_ptr<Args> args_;
  std::vector<std::unique_ptr<PngOutput>> pngs_;  // stable addresses: CLI11 writes into path
  CLI::Option* measure_option_ = nullptr;  // the method's --measure or --fidelity
  std::function<void()> check_;
  std::function<MethodDraft(const MethodInput&)> prepare_;
  std::function<void()> warm_up_;
};

}  // namespace stipplot::cli
