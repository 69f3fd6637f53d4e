// stipplot hatch: the photo's tone in a few bands, each darker band adding a crossed
// direction of parallel lines (after vpype's hatched).
#include <algorithm>
#include <memory>
#include <sstream>

#include "budget/mark_costs.hpp"
#include "cli/commands.hpp"
#include "cli/method_command.hpp"
#include "methods/hatch/hatch.hpp"
#include "methods/palette.hpp"
#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::cli {

namespace {
struct HatchArgs {
  std::string spacing = "auto", blur = "0.8mm", link = "3mm", pens_file;
  hatch::HatchParams p;
};

// The knob's floor: spacings at most this many times the finest.
constexpr double kMinKnob = 1e-3;

void resolve(HatchArgs& a) {
  a.p.spacing_mm = a.spacing == "auto" ? 0 : parse_paper_mm(a.spacing, "--spacing");
  if (a.spacing != "auto" && !(a.p.spacing_mm > 0)) throw UserError("--spacing must be > 0 (or auto: the pen width)");
  a.p.blur_mm = parse_paper_mm(a.blur, "--blur");
  a.p.link_mm = parse_paper_mm(a.link, "--link");
  a.p.validate();
  if (!a.pens_file.empty()) (void)load_palette(a.pens_file);  // a bad palette is refused before any work
}

struct Prepared {
  hatch::ToneMap tone;
  std::vector<hatch::Direction> dirs;
  Page page;
};

MethodResult draw(const Prepared& pr, hatch::HatchParams p, double k) {
  p.spacing_scale = 1 / std::max(k, kMinKnob);
  MethodResult r;
  r.drawing = hatch::hatch_lines(pr.tone, pr.dirs, p, pr.page);
  nlohmann::json& s = r.summary;
  s["levels"] = p.levels;
  s["grid"] = {pr.tone.width, pr.tone.height};
  s["cell_mm"] = pr.tone.cell_mm;
  s["spacing_scale"] = p.spacing_scale;
  s["photo_darkness"] = hatch::photo_darkness(pr.tone);
  s["drawn_darkness"] = hatch::mean_darkness(pr.tone, pr.dirs, p.spacing_scale);
  nlohmann::json dirs = nlohmann::json::array();
  double lo = 1e300, hi = 0;
  for (const auto& d : pr.dirs) {
    const double sp = d.spacing_mm * p.spacing_scale;
    dirs.push_back({{"angle_deg", d.angle_deg}, {"spacing_mm", sp}, {"pen", d.pen.name}});
    if (sp > 0) lo = std::min(lo, sp), hi = std::max(hi, sp);
  }
  s["directions"] = dirs;
  std::ostringstream c;
  c.setf(std::ios::fixed);
  c.precision(2);
  const size_t drawn = static_cast<size_t>(std::count_if(pr.dirs.begin(), pr.dirs.end(), [](const auto& d) { return d.spacing_mm > 0; }));
  c << r.drawing.primitive_count() << " strokes in " << drawn << (drawn == 1 ? " direction" : " directions") << " (" << p.levels
    << " levels";
  if (hi > 0) c << ", spacing " << lo << "-" << hi << " mm";
  c << ", " << pr.tone.width << "x" << pr.tone.height << " grid)";
  r.counts = c.str();
  return r;
}

// The budget's knob k widens every spacing by 1/k: lines and pen lifts both scale with k,
// so the plot time of the finest drawing times k predicts the rest.
MethodDraft prepare(const HatchArgs& a, const MethodInput& in) {
  auto pr = std::make_shared<Prepared>();
  pr->tone = hatch::tone_map(in.image, a.p, in.placement);
  pr->dirs = hatch::directions(pr->tone, a.p, in.placement.pen_width_mm);
  const PageTransform tf = in.placement.transform(in.image.width, in.image.height);
  pr->page = Page{tf.page_w(), tf.page_h()};
  auto full = std::make_shared<MethodResult>(draw(*pr, a.p, 1));
  const double full_s = budget::quick_estimate_seconds(full->drawing, in.costs.motion(), in.costs.plan_options());
  // The finest drawing's tone is the full tone here: a band darker than its pen can hatch
  // stays at the pen's darkest (photo_darkness against drawn_darkness in --json).
  const double finest = hatch::mean_darkness(pr->tone, pr->dirs, 1);
  MethodDraft d;
  d.predict = [full_s](double k) { return k * full_s; };
  d.draw = [pr, full, p = a.p](double k) { return k >= 1 ? *full : draw(*pr, p, k); };
  d.tone_share = [pr, finest](double k) {
    return finest > 0 ? hatch::mean_darkness(pr->tone, pr->dirs, 1 / std::max(k, kMinKnob)) / finest : 1.0;
  };
  d.ink_needed = finest;
  return d;
}
}  // namespace

void register_hatch(CLI::App& app) {
  auto args = std::make_shared<HatchArgs>();
  auto m = MethodCommand::add(
      app, "hatch", "Tone hatching: a few grey levels, each darker one adding a crossed direction of lines",
      "The photo's grey, blurred on paper (--blur), is split into --levels bands; band b of N is hatched with b\n"
      "directions of parallel lines (45, 135, 0, 90 degrees, ... from --angle), each direction running over\n"
      "every band at least as dark as its own, so long pen-down lines lay the tone with few lifts. Each\n"
      "direction's spacing is set so its ink lays the band's mean darkness; --time widens them all alike.\n"
      "Lines are clipped to their bands; neighbouring lines are joined into zig-zags where the link is short\n"
      "(--link) and stays inside. --contours also traces the bands' boundaries. --pens spreads a palette's\n"
      "pens light to dark over the directions (its greys and blacks only, when it has any).\n"
      "Example: stipplot hatch photo.jpg -o photo.svg --preview photo.png\n"
      "         stipplot hatch photo.jpg -o photo.gcode --levels 4 --contours --time 30min\n"
      "         stipplot hatch photo.jpg -o photo.svg --pens examples/pens/fineliner12.toml --spacing 0.6mm");
  CLI::App* cmd = m->cli();
  const char* g = "Hatch";
  cmd->add_option("--levels", args->p.levels, "Tone bands, white included (2-9): band b gets b crossed directions")
      ->capture_default_str()->group(g);
  cmd->add_option("--spacing", args->spacing,
                  "Closest two lines of one direction may be: mm (0.6, 0.6mm), cm, in, pt or px (1/96 in); auto: the pen width")
      ->capture_default_str()->group(g);
  cmd->add_option("--blur", args->blur, "Gaussian blur (sigma) of the grey on paper before the bands: mm, cm, in, pt or px")
      ->capture_default_str()->group(g);
  cmd->add_option("--angle", args->p.angle_deg, "First direction in degrees, counter-clockwise from +x; the others cross it")
      ->capture_default_str()->group(g);
  cmd->add_option("--link", args->link,
                  "Longest zig-zag link between neighbouring lines (a link straight across is always allowed): mm, cm, in, pt or px")
      ->capture_default_str()->group(g);
  cmd->add_flag("--contours", args->p.contours, "Also draw the bands' boundaries as lines")->group(g);
  cmd->add_option("--pens", args->pens_file, "TOML palette (see examples/pens/): its pens (greys and blacks, if any) light to dark over the directions")
      ->group(g);
  m->define(
      [args] { resolve(*args); },
      [args](const MethodInput& in) {
        HatchArgs a = *args;
        if (!a.pens_file.empty()) a.p.pens = load_palette(a.pens_file, in.placement.pen_width_mm).pens;
        return prepare(a, in);
      });
}

}  // namespace stipplot::cli
