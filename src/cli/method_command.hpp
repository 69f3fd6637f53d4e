#pragma once
// The one command line every drawing method goes through (stipple, tree, sketch,
// pointillism), after vpype's `generator` decorator: the options all methods share are
// added once, and the one path from a method's Drawing to its outputs is written once:
// check every option and output before any work, load the image, run the method, then
// -o (SVG, or planned G-code/HPGL), the preview PNG, the method's extra PNGs, its
// measurements, the --json line and the "wrote ..." sentence. A cmd_*.cpp adds only its
// own options and turns an image into a MethodResult; anything to do to every method's
// drawing on its way to the outputs belongs in MethodCommand::run.
#include <CLI/CLI.hpp>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/common.hpp"
#include "geometry/drawing.hpp"
#include "geometry/page.hpp"
#include "image/image.hpp"
#include "methods/placement.hpp"

namespace stipplot::cli {

class MethodRun;

// What a method is given.
struct MethodInput {
  const Image& image;
  const Placement& placement;
  bool show_progress = false;  // a progress bar is welcome (no --json, no --quiet)
};

// What a method hands to the shared output path.
struct MethodResult {
  Drawing drawing;
  nlohmann::json summary = nlohmann::json::object();  // the method's own --json fields
  // The sentence's middle: "wrote OUT: <counts> in 1.23 s", e.g. "1234 dots in 1 layer
  // (gray, 640x480 px)".
  std::string counts;
  // The preview is the Drawing as drawn on its paper: translucent ink multiplying with
  // what is under it, or (false) opaque paint covering it ...
  bool ink_multiplies = true;
  // ... unless the method renders its marks itself (the sketch averages overlapping
  // colours); called at most once, at --preview-dpi.
  std::function<Image(double dpi)> render_preview;
  // The images of the method's extra PNG options, by option name ("--terrain"); each is
  // made only when its option was given.
  std::map<std::string, std::function<Image()>> images;
  // Measurements once every file is written (see MethodRun).
  std::function<void(MethodRun&)> measure;
};

// What a method's measurement sees and adds to.
class MethodRun {
 public:
  MethodRun(const Image& input, const PageTransform& transform, const MethodResult& result, double preview_dpi,
            nlohmann::json& summary);
  const Image& input;
  const PageTransform& transform;  // how the image lies on the page
  const MethodResult& result;
  nlohmann::json& summary;
  // Appends "; <label> <value>" (two decimals) to the sentence, before the preview is
  // named: "; mean dE00 4.20".
  void note(const std::string& label, double value);
  const std::string& notes() const { return notes_; }
  // The preview (rendered once, at --preview-dpi) cut to the image's rectangle.
  Image preview_over_image();
  // The preview as a whole page, rendered once; written to --preview by MethodCommand.
  const Image& preview_page();
  // The Drawing rendered at one pixel per input pixel and cut to the image's rectangle:
  // what a measure compares with the input pixel by pixel.
  Image drawing_over_image(bool ink_multiplies) const;

 private:
  double preview_dpi_;
  std::string notes_;
  std::unique_ptr<Image> preview_;
};

// "640x480 px", as the sentences give an image's size.
std::string pixel_size(const Image& image);

class MethodCommand {
 public:
  // Adds subcommand `name` with the shared options: IN, -o, --profile and planning,
  // --preview, --preview-dpi, --json, --quiet, --max-pixels, and the page options.
  static std::shared_ptr<MethodCommand> add(CLI::App& app, const std::string& name, const std::string& description,
                                            const std::string& footer);
  CLI::App* cli() const { return cmd_; }

  // An extra PNG the method can write: checked (.png, directory exists) with -o before
  // any work, filled from MethodResult::images, reported under `json_key`, and named in
  // the sentence after the preview as "; <sentence_word> PATH" unless the word is empty.
  void add_png_output(const std::string& option, const std::string& help, const std::string& json_key,
                      const std::string& sentence_word);

  // The method: `check` turns its options into parameters before any file is read or
  // written (throws UserError); `draw` runs it.
  void define(std::function<void()> check, std::function<MethodResult(const MethodInput&)> draw);

 private:
  MethodCommand() = default;
  void run() const;
  void check_outputs() const;
  // `out` is the drawing for -o: r.drawing laid out for the device, or r.drawing itself.
  void write_outputs(MethodResult& r, const Drawing& out, MethodRun& run, nlohmann::json& s) const;
  std::string sentence(const MethodResult& r, const MethodRun& run, const nlohmann::json& s) const;

  struct Args;
  struct PngOutput {
    std::string option, json_key, sentence_word, path;
  };
  CLI::App* cmd_ = nullptr;
  std::string name_;
  std::shared_ptr<Args> args_;
  std::vector<std::unique_ptr<PngOutput>> pngs_;  // stable addresses: CLI11 writes into path
  std::function<void()> check_;
  std::function<MethodResult(const MethodInput&)> draw_;
};

}  // namespace stipplot::cli
