#include "cli/method_command.hpp"

#include <algorithm>
#include <optional>
#include <sstream>

#include "cli/layout_options.hpp"
#include "eval/fidelity.hpp"
#include "preview/preview.hpp"
#include "svg/svg_writer.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"
#include "util/output_paths.hpp"

namespace stipplot::cli {

struct MethodCommand::Args {
  std::string input, output, preview;
  std::string profile = "grbl-servo";  // for .gcode/.hpgl outputs
  PlanArgs plan;                       // for .gcode/.hpgl outputs
  LayoutArgs layout;                   // for outputs to a device, or when asked
  CLI::Option* profile_option = nullptr;
  CLI::Option* page_option = nullptr;
  double preview_dpi = 150;
  uint64_t max_pixels = 100'000'000;
  PlacementArgs place;
  ReportArgs report;
};

MethodRun::MethodRun(const Image& in, const PageTransform& tf, const MethodResult& r, double preview_dpi,
                     nlohmann::json& s)
    : input(in), transform(tf), result(r), summary(s), preview_dpi_(preview_dpi) {}

void MethodRun::note(const std::string& label, double value) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(2);
  os << "; " << label << " " << value;
  notes_ += os.str();
}

const Image& MethodRun::preview_page() {
  if (!preview_) {
    if (result.render_preview) {
      preview_ = std::make_unique<Image>(result.render_preview(preview_dpi_));
    } else {
      PreviewOptions po;
      po.dpi = preview_dpi_;
      po.ink_multiplies = result.ink_multiplies;
      preview_ = std::make_unique<Image>(render_preview(result.drawing, po));
    }
  }
  return *preview_;
}

Image MethodRun::preview_over_image() { return crop_to_image(preview_page(), transform, input.width, input.height); }

Image MethodRun::drawing_over_image(bool ink_multiplies) const {
  PreviewOptions po;
  po.dpi = std::clamp(25.4 / transform.mm_per_px(), 10.0, 2400.0);
  po.ink_multiplies = ink_multiplies;
  return crop_to_image(render_preview(result.drawing, po), transform, input.width, input.height);
}

std::string pixel_size(const Image& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height) + " px";
}

std::shared_ptr<MethodCommand> MethodCommand::add(CLI::App& app, const std::string& name,
                                                  const std::string& description, const std::string& footer) {
  std::shared_ptr<MethodCommand> m(new MethodCommand);
  m->name_ = name;
  m->args_ = std::make_shared<Args>();
  Args& a = *m->args_;
  CLI::App* cmd = app.add_subcommand(name, description);
  cmd->footer(footer);
  cmd->add_option("input", a.input, "Input image (PNG, JPEG, BMP, TGA)")->required();
  cmd->add_option("-o,--output", a.output,
                  "Output file: .svg (the drawing), .gcode (grbl) or .hpgl (planned for --profile)")
      ->required()->group("Output");
  a.profile_option =
      cmd->add_option("--profile", a.profile,
                      "Device profile NAME or PATH for .gcode/.hpgl, whose sheet is the default page (see `stipplot profiles`)")
          ->capture_default_str()->group("Output");
  add_plan_options(cmd, a.plan);
  add_layout_options(cmd, a.layout, false);
  cmd->add_option("--preview", a.preview, "Also write a preview PNG of what the pens will draw")->group("Output");
  cmd->add_option("--preview-dpi", a.preview_dpi, "Preview resolution")->capture_default_str()->group("Output");
  add_report_options(cmd, a.report);
  cmd->add_option("--max-pixels", a.max_pixels, "Refuse images with more pixels than this")
      ->capture_default_str()->group("Input");
  add_placement_options(cmd, a.place);
  a.page_option = cmd->get_option("--page");
  m->cmd_ = cmd;
  // The app owns the callback, the callback keeps the command alive.
  cmd->callback([m] { m->run(); });
  return m;
}

void MethodCommand::add_png_output(const std::string& option, const std::string& help, const std::string& json_key,
                                   const std::string& sentence_word) {
  pngs_.push_back(std::make_unique<PngOutput>(PngOutput{option, json_key, sentence_word, {}}));
  cmd_->add_option(option, pngs_.back()->path, help)->group("Output");
}

void MethodCommand::define(std::function<void()> check, std::function<MethodResult(const MethodInput&)> draw) {
  check_ = std::move(check);
  draw_ = std::move(draw);
}

void MethodCommand::check_outputs() const {
  const Args& a = *args_;
  const OutputKind kind = output_kind(a.output);
  check_profile_for(kind, a.output, a.profile);
  (void)a.plan.resolve();  // even for an SVG, which is not planned: no option is silently ignored
  if (!a.preview.empty()) require_png_path("--preview", a.preview);
  require_range("--preview-dpi", a.preview_dpi, 10, 2400);
  if (a.max_pixels == 0) throw UserError("--max-pixels must be at least 1");
  std::vector<NamedPath> outputs{{"-o", a.output}, {"--preview", a.preview}};
  for (const auto& p : pngs_) {
    if (!p->path.empty()) require_png_path(p->option, p->path);
    outputs.push_back({p->option, p->path});
  }
  check_output_paths({{"input", a.input}}, outputs);
}

namespace {

// The device a method's drawing is laid out for: the profile of a .gcode/.hpgl output, or
// one named with --profile for an SVG; none for a plain SVG.
std::optional<DeviceProfile> layout_device(const std::string& output, const std::string& profile, bool profile_given) {
  if (output_kind(output) == OutputKind::svg && !profile_given) return std::nullopt;
  return find_profile(profile);
}

// A method's page for a device: the paper (--page, else the device's sheet), upright unless
// --landscape (the layout turns it to the sheet), with a margin no narrower than the
// border of the sheet the device cannot reach, so the drawing lands inside the travel.
Placement placement_for_device(Placement p, const LayoutArgs& sheet_args, const DeviceProfile& device, bool page_given) {
  const Page sheet = sheet_for(sheet_args, device);
  if (!page_given) p.page = {std::min(sheet.width_mm, sheet.height_mm), std::max(sheet.width_mm, sheet.height_mm)};
  p.margin_mm = std::max(p.margin_mm, unreachable_border_mm(device, sheet));
  return p;
}

}  // namespace

void MethodCommand::run() const {
  const auto t0 = std::chrono::steady_clock::now();
  const Args& a = *args_;
  check_();
  Placement placement = a.place.resolve();
  check_outputs();
  check_layout_args(a.layout);
  const bool page_given = a.page_option && a.page_option->count() > 0;
  const auto device = layout_device(a.output, a.profile, a.profile_option && a.profile_option->count() > 0);
  LayoutArgs sheet_args = a.layout;  // the method's own --page is the paper it is laid on
  if (page_given) sheet_args.page = a.place.page;
  if (device) placement = placement_for_device(placement, sheet_args, *device, page_given);
  LoadOptions lo;
  lo.max_pixels = a.max_pixels;
  const Image image = load_image(a.input, lo);
  // For a device the page is turned like the photo: a landscape photo lies across it, a
  // portrait one is turned to the sheet by the layout.
  if (device && !a.place.landscape) placement.landscape = image.width > image.height;
  const auto t1 = std::chrono::steady_clock::now();
  MethodResult r = draw_(MethodInput{image, placement, !a.report.json && !a.report.quiet});
  const double method_s = seconds_since(t1);

  nlohmann::json s = r.summary;
  s["command"] = name_;
  s["input"] = a.input;
  s["image_px"] = {image.width, image.height};
  const PageTransform tf = placement.transform(image.width, image.height);
  MethodRun mr(image, tf, r, a.preview_dpi, s);
  // -o gets the drawing laid out for the device; the preview and the measurements keep
  // the method's page, where the image lies as the transform says.
  std::string laid_out;
  const bool lay_out = device || a.layout.any_given();
  const Drawing out = lay_out ? lay_out_for_device(r.drawing, sheet_args, device ? &*device : nullptr,
                                                   placement.margin_mm, s, laid_out)
                              : Drawing{};
  write_outputs(r, lay_out ? out : r.drawing, mr, s);
  if (r.measure) r.measure(mr);
  s["seconds_method"] = method_s;
  s["seconds"] = seconds_since(t0);
  a.report.print(s, sentence(r, mr, s) + (laid_out.empty() ? "" : "; " + laid_out));
}

void MethodCommand::write_outputs(MethodResult& r, const Drawing& d, MethodRun& run, nlohmann::json& s) const {
  const Args& a = *args_;
  if (output_kind(a.output) == OutputKind::svg) {
    write_svg(d, a.output);
    s["output"] = a.output;
  } else {
    write_planned_output(d, a.output, a.profile, a.plan, false, s);
  }
  if (!a.preview.empty()) {
    if (r.render_preview) {
      write_png(run.preview_page(), a.preview);
    } else {
      PreviewOptions po;
      po.dpi = a.preview_dpi;
      po.ink_multiplies = r.ink_multiplies;
      write_preview_png(d, a.preview, po);
    }
    s["preview"] = a.preview;
  }
  for (const auto& p : pngs_) {
    if (p->path.empty()) continue;
    const auto make = r.images.find(p->option);
    if (make == r.images.end()) throw std::logic_error(name_ + " gave no image for " + p->option);
    write_png(make->second(), p->path);
    s[p->json_key] = p->path;
  }
  nlohmann::json layers = nlohmann::json::array();
  for (const auto& l : d.layers)
    layers.push_back({{"pen", l.pen.name},
                      {"color", l.pen.color.hex()},
                      {"dots", l.dots.size()},
                      {"lines", l.lines.size()},
                      {"circles", l.circles.size()}});
  s["layers"] = layers;
  s["primitives"] = d.primitive_count();
  s["page_mm"] = {d.page.width_mm, d.page.height_mm};
}

std::string MethodCommand::sentence(const MethodResult& r, const MethodRun& run, const nlohmann::json& s) const {
  const Args& a = *args_;
  std::ostringstream h;
  h.setf(std::ios::fixed);
  h.precision(2);
  h << "wrote " << a.output << ": " << r.counts << " in " << s["seconds"].get<double>() << " s" << run.notes();
  if (!a.preview.empty()) h << "; preview " << a.preview;
  for (const auto& p : pngs_)
    if (!p->path.empty() && !p->sentence_word.empty()) h << "; " << p->sentence_word << " " << p->path;
  return h.str();
}

}  // namespace stipplot::cli
