#include "cli/method_command.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include "budget/density_search.hpp"
#include "budget/duration.hpp"
#include "cli/layout_options.hpp"
#include "drivers/motion/plan_stats.hpp"
#include "eval/fidelity.hpp"
#include "eval/view.hpp"
#include "layout/clip.hpp"
#include "plan/planner.hpp"
#include "preview/preview.hpp"
#include "svg/svg_writer.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"
#include "util/even_share.hpp"
#include "util/output_paths.hpp"
#include "util/threads.hpp"

namespace stipplot::cli {

struct MethodCommand::Args {
  std::string input, output, preview;
  std::string profile = "grbl-servo";  // the plotter: its time model sets the budget, its writer .gcode/.hpgl
  PlanArgs plan;
  std::string time = "1h";             // the plot-time budget on the profile
  double knob = -1;                    // >= 0: this density, no search (the benchmark's one run)
  LayoutArgs layout;                   // for outputs to a device, or when asked
  CLI::Option* profile_option = nullptr;
  CLI::Option* page_option = nullptr;
  double preview_dpi = 150;
  uint64_t max_pixels = 100'000'000;
  PlacementArgs place;
  ReportArgs report;
  std::string view_sigma = "1mm";      // the viewing-distance blur every measure reports at
  CLI::Option* view_sigma_option = nullptr;
  bool measure = false;                // the --measure of a method without one of its own
  int threads = 0;                     // 0: one per core (util/threads.hpp)
  bool draft = false;                  // a quick look (the studio's while a control moves)
};

MethodRun::MethodRun(const Image& in, const PageTransform& tf, const MethodResult& r, const Plan& p,
                     double preview_dpi, nlohmann::json& s)
    : input(in), transform(tf), result(r), plan(p), summary(s), preview_dpi_(preview_dpi) {}

namespace {
// The one render of what will be drawn: the plan with real pens, or the drawing's
// primitives in their screen colours.
Image render_result(const MethodResult& r, const Plan& plan, double dpi, bool opaque) {
  PreviewOptions po;
  po.dpi = dpi;
  po.ink_multiplies = !opaque && !r.screen_colours;
  return r.screen_colours ? render_preview(r.drawing, po) : render_plan(plan, po);
}
}  // namespace

void MethodRun::note(const std::string& label, double value) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(2);
  os << "; " << label << " " << value;
  notes_ += os.str();
}

void MethodRun::render_preview_beside() {
  if (preview_ || rendering_.valid()) return;
  // The render reads the result and the plan only, which nothing changes meanwhile.
  rendering_ = std::async(std::launch::async, [this] { preview_ = std::make_unique<Image>(render_preview_page()); });
}

Image MethodRun::render_preview_page() const {
  return result.render_preview ? result.render_preview(preview_dpi_) : render_result(result, plan, preview_dpi_, false);
}

const Image& MethodRun::preview_page() {
  if (rendering_.valid()) rendering_.get();  // rethrows the render's error
  if (!preview_) preview_ = std::make_unique<Image>(render_preview_page());
  return *preview_;
}

Image MethodRun::preview_over_image() { return crop_to_image(preview_page(), transform, input.width, input.height); }

Image MethodRun::render_over_image(bool opaque) const {
  // Pens of a few tenths of a millimetre need some pixels across to be measured right.
  const double dpi = std::clamp(25.4 / transform.mm_per_px(), 150.0, 1200.0);
  return crop_to_image(render_result(result, plan, dpi, opaque), transform, input.width, input.height);
}

Image MethodRun::render_page(double px_per_mm) const { return render_result(result, plan, 25.4 * px_per_mm, false); }

MethodDraft fixed_density(std::function<MethodResult()> draw) {
  MethodDraft d;
  d.predict = [](double) { return 0.0; };
  d.draw = [draw = std::move(draw)](double) { return draw(); };
  return d;
}

namespace {
template <class T>
std::vector<T> thin_list(const std::vector<T>& v, double k) {
  if (k >= 1) return v;
  std::vector<T> out;
  out.reserve(static_cast<size_t>(static_cast<double>(v.size()) * k) + 1);
  for (size_t i = 0; i < v.size(); ++i)
    if (in_even_share(i, k)) out.push_back(v[i]);
  return out;
}

// Ink a drawing lays, as a share of its page's area: pen width x stroke length, disc
// areas. An estimate (overlaps count twice), for the result line.
double ink_share(const Drawing& d) {
  double ink = 0;
  for (const Layer& l : d.layers) {
    const double w = l.pen.width_mm;
    for (const Polyline& pl : l.lines)
      for (size_t i = 1; i < pl.pts.size(); ++i)
        ink += w * std::hypot(pl.pts[i].x - pl.pts[i - 1].x, pl.pts[i].y - pl.pts[i - 1].y);
    for (const Dot& dot : l.dots) ink += 0.25 * M_PI * std::max(dot.diameter, w) * std::max(dot.diameter, w);
    for (const Circle& c : l.circles) ink += c.filled ? M_PI * c.r * c.r : 2 * M_PI * c.r * w;
  }
  const double area = d.page.width_mm * d.page.height_mm;
  return area > 0 ? std::min(1.0, ink / area) : 0;
}
}  // namespace

Drawing thin_marks(const Drawing& d, double k) {
  Drawing out;
  out.page = d.page;
  for (const Layer& l : d.layers) {
    Layer t;
    t.pen = l.pen;
    t.dots = thin_list(l.dots, k);
    t.lines = thin_list(l.lines, k);
    t.circles = thin_list(l.circles, k);
    t.areas = thin_list(l.areas, k);
    if (t.primitive_count() > 0) out.layers.push_back(std::move(t));
  }
  return out;
}

MethodDraft spaced_density(const MethodInput& in, std::function<MethodResult(double spacing)> draw) {
  auto full = std::make_shared<MethodResult>(draw(1.0));
  const budget::MarkCosts& c = in.costs;
  const double full_s = budget::quick_estimate_seconds(full->drawing, c.motion(), c.plan_options());
  MethodDraft d;
  d.predict = [full_s](double k) { return k * full_s; };
  d.draw = [full, draw = std::move(draw)](double k) {
    if (k >= 1) return *full;
    MethodResult r = draw(1 / std::sqrt(std::max(k, 1e-4)));
    r.summary["spacing_scale"] = 1 / std::sqrt(std::max(k, 1e-4));
    return r;
  };
  d.ink_needed = ink_share(full->drawing);
  return d;
}

MethodDraft thinned_density(const MethodInput& in, std::function<MethodResult()> draw) {
  auto full = std::make_shared<MethodResult>(draw());
  const budget::MarkCosts& c = in.costs;
  const double full_s = budget::quick_estimate_seconds(full->drawing, c.motion(), c.plan_options());
  MethodDraft d;
  d.predict = [full_s](double k) { return k * full_s; };
  d.draw = [full](double k) {
    if (k >= 1) return *full;
    MethodResult r = *full;
    r.drawing = thin_marks(full->drawing, k);
    // The method's own preview shows every mark: the pen-true render of the plan shows
    // what is kept.
    r.render_preview = nullptr;
    const size_t n = r.drawing.primitive_count();
    r.counts = std::to_string(n) + " of " + std::to_string(full->drawing.primitive_count()) + " marks (" + r.counts + ")";
    r.summary["marks_kept"] = n;
    return r;
  };
  d.tone_share = [](double k) { return k; };
  d.ink_needed = ink_share(full->drawing);
  return d;
}

MethodDraft scaled_density(const MethodInput& in, std::function<MethodResult(double k)> draw,
                           std::function<double(double k)> time_share) {
  auto full = std::make_shared<MethodResult>(draw(1.0));
  const budget::MarkCosts& c = in.costs;
  const double full_s = budget::quick_estimate_seconds(full->drawing, c.motion(), c.plan_options());
  MethodDraft d;
  if (time_share) d.predict = [full_s, time_share](double k) { return full_s * time_share(k); };
  else d.predict = [full_s](double k) { return k * full_s; };
  d.draw = [full, draw = std::move(draw)](double k) { return k >= 1 ? *full : draw(k); };
  d.tone_share = [](double k) { return k; };
  d.ink_needed = ink_share(full->drawing);
  return d;
}

std::string pixel_size(const Image& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height) + " px";
}

// The one rule for lengths, in every method's --help (README "Lengths").
constexpr const char* kLengthRule =
    "Lengths: a number and its unit: mm, cm, in, pt or px. A bare number is mm where only paper is\n"
    "meant (--margin 10). Where a length can be on paper or in input pixels (stipple -a, -b, --dot-size,\n"
    "sketch --cell), a bare number is refused: write 3px (input pixels) or 0.2mm.";

std::shared_ptr<MethodCommand> MethodCommand::add(CLI::App& app, const std::string& name,
                                                  const std::string& description, const std::string& footer) {
  std::shared_ptr<MethodCommand> m(new MethodCommand);
  m->name_ = name;
  m->args_ = std::make_shared<Args>();
  Args& a = *m->args_;
  CLI::App* cmd = app.add_subcommand(name, description);
  cmd->footer(footer + "\n" + kLengthRule);
  cmd->add_option("input", a.input, "Input image (PNG, JPEG, BMP, TGA)")->required();
  cmd->add_option("-o,--output", a.output,
                  "Output file: .svg (the drawing), .gcode (grbl) or .hpgl (planned for --profile)")
      ->required()->group("Output");
  a.profile_option =
      cmd->add_option("--profile", a.profile,
                      "Device profile NAME or PATH (see `stipplot profiles`): the plotter the --time budget is for, "
                      "the writer of .gcode/.hpgl/.ebb, whose sheet is the default page when named or written for")
          ->capture_default_str()->group("Output");
  cmd->add_option("--time", a.time,
                  "Plot-time budget on --profile (45min, 1h, 1.5h, 1h30min): the density is chosen so the planned "
                  "plot fits it")
      ->capture_default_str()->group("Output");
  // Hidden: the benchmark's baseline, one run of the method at the density a search chose.
  cmd->add_option("--knob", a.knob, "Draw at this density knob (0..1) without searching for --time")
      ->check(CLI::Range(0.0, 1.0))->group("");
  add_plan_options(cmd, a.plan);
  add_layout_options(cmd, a.layout, false);
  cmd->add_option("--preview", a.preview, "Also write a preview PNG of what the pens will draw")->group("Output");
  cmd->add_option("--preview-dpi", a.preview_dpi, "Preview resolution")->capture_default_str()->group("Output");
  cmd->add_flag("--draft", a.draft,
               "A quick look, as the studio shows while a control moves: the method's page grid no finer than the "
               "preview's pixels (--preview-dpi), the greedy tour the budget estimates with; close to the full "
               "drawing and its plot time, not the same")
      ->group("Output");
  add_report_options(cmd, a.report);
  cmd->add_option("--max-pixels", a.max_pixels, "Refuse images with more pixels than this")
      ->capture_default_str()->group("Input");
  cmd->add_option("--threads", a.threads,
                  "Threads for the parallel parts (0: one per core, or OMP_NUM_THREADS if set); the drawing is the same for any count")
      ->capture_default_str()->group("Input");
  add_placement_options(cmd, a.place);
  a.page_option = cmd->get_option("--page");
  a.view_sigma_option =
      cmd->add_option("--view-sigma", a.view_sigma,
                      "The measure's viewing-distance blur on paper, with its unit (1mm, 0.5mm): SSIM and tone r of "
                      "the blurred drawing against the blurred photo")
          ->capture_default_str()->group("Output");
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

void MethodCommand::define(std::function<void()> check, std::function<MethodDraft(const MethodInput&)> prepare) {
  check_ = std::move(check);
  prepare_ = std::move(prepare);
  measure_option_ = cmd_->get_option_no_throw("--measure");
  if (!measure_option_) measure_option_ = cmd_->get_option_no_throw("--fidelity");
  if (!measure_option_)
    measure_option_ = cmd_->add_flag("--measure", args_->measure,
                                     "Report SSIM and tone r of the drawing seen from a viewing distance (--view-sigma)")
                          ->group("Output");
}

void MethodCommand::check_outputs() const {
  const Args& a = *args_;
  const OutputKind kind = output_kind(a.output);
  check_profile_for(kind, a.output, a.profile);
  (void)find_profile(a.profile);
  (void)a.plan.resolve();  // even for an SVG, which is not planned: no option is silently ignored
  (void)budget::parse_duration(a.time);
  if (!a.preview.empty()) require_png_path("--preview", a.preview);
  require_range("--preview-dpi", a.preview_dpi, 10, 2400);
  (void)parse_view_sigma_mm(a.view_sigma);
  if (a.view_sigma_option->count() > 0 && measure_option_->count() == 0)
    throw UserError("--view-sigma is the blur of " + measure_option_->get_name() + ": give " +
                    measure_option_->get_name() + " too");
  if (a.max_pixels == 0) throw UserError("--max-pixels must be at least 1");
  std::vector<NamedPath> outputs{{"-o", a.output}, {"--preview", a.preview}};
  for (const auto& p : pngs_) {
    if (!p->path.empty()) require_png_path(p->option, p->path);
    outputs.push_back({p->option, p->path});
  }
  check_output_paths({{"input", a.input}}, outputs);
}

namespace {

// The smallest knob from `from` up whose drawing has the full tone. Bisection, 40
// evaluations of the draft's tone share.
double full_tone_knob(const MethodDraft& draft, double from) {
  double lo = from, hi = 1;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (draft.tone_share(mid) < 0.995 ? lo : hi) = mid;
  }
  return hi;
}

// The budget's part of the summary and of the sentence.
struct BudgetReport {
  nlohmann::json json;
  std::string words;
};

BudgetReport report_budget(const MethodDraft& draft, const budget::SearchOutcome& so, double budget_s,
                           double plan_s, const std::string& profile) {
  BudgetReport rep;
  const double tone = draft.tone_share ? draft.tone_share(so.knob) : 1.0;
  rep.json = {{"seconds", budget_s},        {"profile", profile},         {"knob", so.knob},
              {"runs", so.runs},            {"quick_estimate_s", so.seconds}, {"predicted_s", so.predicted},
              {"correction", so.correction}, {"finest", so.finest},        {"tone_share", tone},
              {"ink_needed", draft.ink_needed}, {"ink_reached", tone * draft.ink_needed}};
  std::ostringstream w;
  w << "; plot " << budget::format_duration(plan_s) << " on " << profile << " (budget "
    << budget::format_duration(budget_s) << ")";
  if (tone < 0.995 && draft.tone_share) {
    // What the corrected prediction says the full tone costs.
    const double full_s = so.correction * draft.predict(full_tone_knob(draft, so.knob));
    rep.json["seconds_for_full_tone"] = full_s;
    w.setf(std::ios::fixed);
    w.precision(0);
    w << "; tone " << 100 * tone << "% of the photo's (ink on " << 100 * tone * draft.ink_needed << "% of the area, "
      << 100 * draft.ink_needed << "% needed): about --time " << budget::format_duration(full_s)
      << " or a wider pen would reach it";
  } else if (so.finest && plan_s < 0.8 * budget_s) {
    w << "; the finest drawing needs no more";
  }
  rep.words = w.str();
  return rep;
}

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

// The viewing-distance figures of every method's measure (eval/view.hpp), from the render
// the other measures see, at measure.py's 10 px/mm. dE00 for drawings in colour.
void report_view(MethodRun& run, double sigma_mm) {
  ViewOptions vo;
  vo.sigma_mm = sigma_mm;
  vo.colour = run.result.screen_colours;
  for (const Layer& l : run.result.drawing.layers)
    vo.colour = vo.colour || l.pen.color.r != l.pen.color.g || l.pen.color.g != l.pen.color.b;
  const double ppmm = view_px_per_mm(run.transform.page_w(), run.transform.page_h());
  const ViewScore v = view_score(run.input, run.transform, run.render_page(ppmm), vo);
  run.summary["view_sigma_mm"] = sigma_mm;
  run.summary["ssim_view"] = v.ssim;
  run.summary["tone_r_view"] = v.tone_r;
  run.summary["tone_err_view"] = v.tone_err;
  if (vo.colour) run.summary["delta_e_view"] = v.delta_e;
  std::ostringstream at;
  at << "viewed at " << sigma_mm << " mm: SSIM";
  run.note(at.str(), v.ssim);
  run.note("tone r", v.tone_r);
  if (vo.colour) run.note("dE00", v.delta_e);
}

// The method drawn at the density whose plan fits the budget (or at --knob): the density
// search, then one try at the full tone when the prediction says it fits. Every run is
// kept, so the search can fall back to an earlier one at no cost.
MethodResult draw_within_budget(const MethodDraft& draft, double knob, double budget_s, const DeviceProfile& prof,
                                const PlanOptions& po, budget::SearchOutcome& so) {
  std::map<double, MethodResult> runs;
  auto run_at = [&](double k) {
    MethodResult r = draft.draw(k);
    const double t = budget::quick_estimate_seconds(r.drawing, prof.motion, po);
    runs[k] = std::move(r);
    return t;
  };
  budget::SearchOptions so_opt;
  so_opt.budget_s = budget_s;
  if (knob >= 0) {
    so.knob = knob;
    so.seconds = run_at(knob);
    so.predicted = draft.predict(knob);
    so.runs = 1;
  } else {
    so = budget::choose_density(so_opt, draft.predict, run_at, draft.calibrate);
    // The search aims below the budget for the prediction's error; when the full tone is
    // predicted to fit the budget all the same, try it once, keep it if it does.
    if (draft.tone_share && draft.tone_share(so.knob) < 0.995) {
      const double k_full = full_tone_knob(draft, so.knob);
      if (so.correction * draft.predict(k_full) <= budget_s) {
        const double t = run_at(k_full);
        ++so.runs;
        if (t <= budget_s) so.knob = k_full, so.seconds = t;
      }
    }
  }
  return std::move(runs.at(so.knob));
}

}  // namespace

void MethodCommand::run() const {
  const auto t0 = std::chrono::steady_clock::now();
  const Args& a = *args_;
  set_thread_count(a.threads);
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
  std::thread warm_up;
  if (warm_up_ && thread_count() > 1)
    warm_up = std::thread([this] {
      try {
        warm_up_();
      } catch (...) {  // a warm-up only: the work that needs it fails in its own place
      }
    });
  const Image image = [&] {
    struct JoinAtEnd {
      std::thread& t;
      ~JoinAtEnd() {
        if (t.joinable()) t.join();
      }
    } join{warm_up};
    return load_image(a.input, lo);
  }();
  // For a device the page is turned like the photo: a landscape photo lies across it, a
  // portrait one is turned to the sheet by the layout.
  if (device && !a.place.landscape) placement.landscape = image.width > image.height;
  const PageTransform tf = placement.transform(image.width, image.height);
  const DeviceProfile prof = find_profile(a.profile);
  const double budget_s = budget::parse_duration(a.time);
  PlanOptions po = plan_options_for(prof, Page{tf.page_w(), tf.page_h()}, a.plan);
  // A draft's tour is the greedy one the budget's estimates use: its plot time is a few
  // per cent above the improved tour's, which the full run gives.
  if (a.draft) po.optimize_effort = 0, po.optimize_seconds = 0;
  const budget::MarkCosts costs(prof.motion, po);

  const auto t1 = std::chrono::steady_clock::now();
  // The draft may keep references to the input: it lives as long as the draft.
  const MethodInput input{image, placement, costs, !a.report.json && !a.report.quiet, budget_s,
                          a.draft ? 25.4 / a.preview_dpi : 0.0};
  const MethodDraft draft = prepare_(input);
  budget::SearchOutcome so;
  MethodResult r;
  const Vec2 img_lo = tf.map(0, 0), img_hi = tf.map(image.width, image.height);
  layout::ClipCounts clipped;
  // The plan of the method's page: what the preview and the measures render, and the
  // plot time (a layout for the device moves and turns the drawing, which keeps it).
  const bool timed_moves = output_kind(a.output) == OutputKind::gcode || output_kind(a.output) == OutputKind::ebb;
  Plan plan;
  PlanStats stats;
  auto t2 = std::chrono::steady_clock::now();
  double method_s = 0;
  auto finish_drawing = [&] {
    // Each pen taken up once, light inks before dark (a dark pen never drags through a
    // light one's wet ink), whatever the method.
    merge_layers_by_pen(r.drawing);
    // Every mark inside the image's rectangle on the page: strokes shaped near the border
    // must not run past it, nor off a page with no margin.
    clipped = layout::clip_to_rect(r.drawing, Rect{img_lo.x, img_lo.y, img_hi.x, img_hi.y});
  };
  auto make_plan = [&] {
    t2 = std::chrono::steady_clock::now();
    plan = plan_drawing(r.drawing, po);
    stats = plan_stats(plan, prof.motion, po.origin, timed_moves);
  };
  // Over the budget by `seconds` at the knob now: again at a knob below, `margin` below
  // the budget, the step sized by how the time goes with the knob near it: through an
  // earlier (knob, seconds) of the same measure when there is one (a tree's job went as
  // about k^0.4), else as the prediction goes.
  auto redraw_below = [&](double seconds, double margin, std::pair<double, double> before = {0, 0}) {
    const auto t3 = std::chrono::steady_clock::now();
    const double k = so.knob;
    double power = 1;
    if (before.first > 0 && before.second > 0 && before.first != k && before.second != seconds) {
      power = std::log(before.second / seconds) / std::log(before.first / k);
    } else if (const double p = draft.predict(k), p_lower = draft.predict(0.9 * k); p > 0 && p_lower > 0 && p != p_lower) {
      power = std::log(p / p_lower) / std::log(1 / 0.9);
    }
    so.knob = k * std::pow(margin * budget_s / seconds, 1 / std::clamp(power, 0.2, 3.0));
    r = draft.draw(so.knob);
    so.seconds = budget::quick_estimate_seconds(r.drawing, prof.motion, po);
    ++so.runs;
    so.finest = false;
    finish_drawing();
    method_s += seconds_since(t3);
    make_plan();
  };
  r = draw_within_budget(draft, a.knob, budget_s, prof, po, so);
  finish_drawing();
  method_s = seconds_since(t1);
  make_plan();
  // The search judged its runs by the quick estimate; the plan can take a few per cent
  // more (a zig-zag hatching's corners). Over the budget: again, 1.5 % below it (twice at
  // most; then 5 %).
  for (int redo = 0; redo < 2 && a.knob < 0 && so.knob > 0 && stats.total.seconds > budget_s; ++redo)
    redraw_below(stats.total.seconds, redo == 0 ? 0.985 : 0.95);
  // A device's job is timed from its written lines (the wire's pace included: a grbl
  // plotter's 115,200 baud feed 600-odd short lines a second, which a tree's rounded tips
  // outrun): over the budget, the drawing is made again below it and the job rewritten.
  const bool device_job = output_kind(a.output) != OutputKind::svg;
  const bool searched = a.knob < 0 && !a.draft;
  std::pair<double, double> job_before{0, 0};  // an earlier drawing's knob and job seconds
  for (int job_redo = 0;; ++job_redo) {
    nlohmann::json s = r.summary;
    s["command"] = name_;
    s["input"] = a.input;
    s["image_px"] = {image.width, image.height};
    s["clipped_at_image_edge"] = clipped.total();
    s["profile"] = prof.name;
    s["plan"] = to_json(stats);
    s["seconds_plan"] = seconds_since(t2);
    MethodRun mr(image, tf, r, plan, a.preview_dpi, s);
    // The preview renders beside the layout and the writing of -o (a second core's work).
    if (!a.preview.empty()) mr.render_preview_beside();
    // -o gets the drawing laid out for the device; the preview and the measurements keep
    // the method's page, where the image lies as the transform says.
    std::string laid_out;
    const bool lay_out = device || a.layout.any_given();
    const Drawing out = lay_out ? lay_out_for_device(r.drawing, sheet_args, device ? &*device : nullptr,
                                                     placement.margin_mm, s, laid_out)
                                : Drawing{};
    write_outputs(r, lay_out ? &out : nullptr, mr, s);
    // An SVG for a named profile is that device's job too (the studio exports it): timed as
    // one where the link could hold it back, not while a control moves (--draft). An SVG
    // without --profile is not yet for a device: the plan's time.
    if (!device_job && device && !a.draft && link_may_bind(plan, stats.total.seconds, prof))
      time_as_job(plan, prof, s["plan"]);
    const double plot_s = s["plan"]["total"]["seconds"].get<double>();
    if (searched && so.knob > 0 && plot_s > budget_s && job_redo < 3) {
      const std::pair<double, double> now{so.knob, plot_s};
      redraw_below(plot_s, job_redo < 2 ? 0.985 : 0.95, job_before);
      job_before = now;
      continue;
    }
    const BudgetReport budget_report = report_budget(draft, so, budget_s, plot_s, prof.name);
    s["budget"] = budget_report.json;
    if (r.measure) r.measure(mr);
    if (measure_option_->count() > 0) report_view(mr, parse_view_sigma_mm(a.view_sigma));
    s["seconds_method"] = method_s;
    s["seconds"] = seconds_since(t0);
    a.report.print(s, sentence(r, mr, s, budget_report.words) + (laid_out.empty() ? "" : "; " + laid_out));
    return;
  }
}

void MethodCommand::write_outputs(MethodResult& r, const Drawing* laid_out, MethodRun& run, nlohmann::json& s) const {
  const Args& a = *args_;
  const Drawing& d = laid_out ? *laid_out : r.drawing;
  const auto t0 = std::chrono::steady_clock::now();
  if (output_kind(a.output) == OutputKind::svg) {
    write_svg(d, a.output);
  } else if (laid_out) {
    // Laid out for the device: planned again on its sheet (the summary's plan is this one).
    write_planned_output(d, a.output, a.profile, a.plan, false, s);
  } else {
    write_plan_file(run.plan, a.output, find_profile(a.profile), false, &s["plan"]);
  }
  s["output"] = a.output;
  s["seconds_write"] = seconds_since(t0);
  if (!a.preview.empty()) {
    write_png(run.preview_page(), a.preview);
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

std::string MethodCommand::sentence(const MethodResult& r, const MethodRun& run, const nlohmann::json& s,
                                    const std::string& budget_words) const {
  const Args& a = *args_;
  std::ostringstream h;
  h.setf(std::ios::fixed);
  h.precision(2);
  h << "wrote " << a.output << ": " << r.counts << " in " << s["seconds"].get<double>() << " s" << budget_words << run.notes();
  if (!a.preview.empty()) h << "; preview " << a.preview;
  for (const auto& p : pngs_)
    if (!p->path.empty() && !p->sentence_word.empty()) h << "; " << p->sentence_word << " " << p->path;
  return h.str();
}

}  // namespace stipplot::cli
