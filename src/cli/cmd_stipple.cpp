// stipplot stipple: grayscale-order Poisson disk stippling (seed 000), on the page for
// tone, with the density chosen for the plot-time budget.
#include <cmath>
#include <map>
#include <memory>

#include "cli/commands.hpp"
#include "cli/method_command.hpp"
#include "cli/pen_choice.hpp"
#include "budget/density_search.hpp"
#include "budget/mark_costs.hpp"
#include "methods/palette.hpp"
#include "methods/stipple/connect.hpp"
#include "methods/stipple/stipple.hpp"
#include "util/error.hpp"
#include "util/progress.hpp"

namespace stipplot::cli {

namespace {
struct StippleArgs {
  std::string method = "gray";
  std::string law = "tone";
  bool law_given = false, linear_given = false;  // -a ... --b-w ask for the linear law
  std::string max_dot;  // empty: chosen by the budget
  std::string a = "3px", b = "15px", a_b = "3px", b_b = "15px", a_w = "3px", b_w = "15px";
  uint64_t seed = 1;
  StippleMethod m = StippleMethod::Gray;
  PageStipple page;
  double max_dot_mm = 0;  // 0 = the budget's
  std::string pens_file;  // color and cmyk: draw the separation's inks with these pens
  int max_pens = -1;  // not given
  std::vector<Pen> palette;
  bool connect = false;  // TSP art: the points joined by one line (methods/stipple/connect.hpp)
  bool dots = false;     // the dot stipple, whatever the budget (neither: chosen by the budget)
  double lift_length = 3, lift_tone = 0.5;
  bool lift_given = false;
};

// A process ink with no palette pen this near (CIEDE2000) would be drawn in a colour
// that is not its own: the separation would be wrong, not merely approximate.
constexpr double kCmykInkReach = 30;

// Every process ink has a palette pen near it, or one line naming the ink that has none.
void check_cmyk_palette(const std::vector<Pen>& palette, const std::string& file) {
  for (const Pen& ink : cmyk_inks()) {
    double best = std::numeric_limits<double>::infinity();
    std::string nearest;
    for (const Pen& p : palette) {
      const double d = ink_distance(ink.color, p.color, InkMatch::hue);
      if (d < best) best = d, nearest = p.name;
    }
    if (best > kCmykInkReach) {
      std::ostringstream os;
      os.setf(std::ios::fixed);
      os.precision(0);
      os << "--pens " << file << ": -m cmyk needs a pen near " << ink.name << " (the nearest, '" << nearest
         << "', is dE00 " << best << " away, more than " << kCmykInkReach
         << "); use -m color, which draws with any palette, or -m gray";
      throw UserError(os.str());
    }
  }
}

// Whether the budget may choose the connected drawing: one ink (gray, random, negative)
// with the tone law, and nothing that sizes dots.
bool connectable(const StippleArgs& a) {
  return (a.m == StippleMethod::Gray || a.m == StippleMethod::Random || a.m == StippleMethod::Negative) &&
         a.page.law == StippleLaw::Tone && a.max_dot.empty() && a.pens_file.empty();
}

// With neither --connect nor --dots the budget chooses the connected drawing (TSP art)
// when the budget is under kConnectBelow times the time the line's whole tone needs, or
// when the dot stipple would need dots wider than kBlobPens pen widths at this budget (the
// predicted knob's largest dot: filled discs that keep the tone and lose the picture);
// else the dots, whose fine dots then lay the tone and the detail better. On the shared
// photos (README, SSIM at 1 mm): at 1 h the line for coffee, horse and rocket (0.79 / 0.99 /
// 0.66 against the dots' 0.38 / 0.96 / 0.28: 4.6-4.75 mm discs); at 4 h the dots for coffee
// and horse (0.95 / 1.00 against 0.89 / 0.99: 2.0 and 1.5 mm), the line for rocket (0.92 both).
constexpr double kConnectBelow = 2;
constexpr double kBlobPens = 10;

void resolve(StippleArgs& a) {
  a.m = parse_stipple_method(a.method);
  a.page.law = parse_stipple_law(a.law);
  if (a.linear_given && !a.law_given) a.page.law = StippleLaw::Linear;
  if (a.linear_given && a.page.law == StippleLaw::Tone)
    throw UserError("-a, -b, --a-b, --b-b, --a-w and --b-w belong to --law linear, not --law tone");
  a.page.a = Length::parse(a.a, "-a");
  a.page.b = Length::parse(a.b, "-b");
  a.page.a_b = Length::parse(a.a_b, "--a-b");
  a.page.b_b = Length::parse(a.b_b, "--b-b");
  a.page.a_w = Length::parse(a.a_w, "--a-w");
  a.page.b_w = Length::parse(a.b_w, "--b-w");
  a.max_dot_mm = a.max_dot.empty() ? 0 : parse_paper_mm(a.max_dot, "--max-dot");
  if (!a.max_dot.empty()) require_range("--max-dot", a.max_dot_mm, 0.01, 100);
  a.page.validate();
  a.palette.clear();
  if (!a.pens_file.empty()) {
    if (a.m != StippleMethod::Color && a.m != StippleMethod::Cmyk)
      throw UserError("--pens applies to -m color and -m cmyk (the other methods draw in one ink)");
    a.palette = load_palette(a.pens_file).pens;
    if (a.m == StippleMethod::Cmyk && a.max_pens < 1) check_cmyk_palette(a.palette, a.pens_file);
  }
  check_max_pens(a.max_pens, a.palette.size(), a.pens_file);
  if (a.connect && a.dots) throw UserError("--connect and --dots: give one (neither: the budget chooses)");
  if (a.connect) {
    if (a.m != StippleMethod::Gray && a.m != StippleMethod::Random && a.m != StippleMethod::Negative)
      throw UserError(std::string("--connect draws one line with one pen: use -m gray, random or negative, not -m ") +
                      to_string(a.m));
    if (a.page.law != StippleLaw::Tone)
      throw UserError("--connect spaces its points for the line's tone: it belongs to --law tone, not --law linear");
    if (!a.max_dot.empty()) throw UserError("--max-dot sizes dots: --connect draws lines, not dots");
    ConnectParams p;
    p.lift_length = a.lift_length;
    p.lift_tone = a.lift_tone;
    p.relax = a.page.relax;
    p.validate();
  } else if (a.lift_given && (a.dots || !connectable(a))) {
    throw UserError("--lift-length and --lift-tone belong to --connect");
  }
}

// --json "style_choice": why the budget drew dots or a line.
nlohmann::json style_choice(bool connect, double connect_full_s, double dots_max_mm, double pen_mm) {
  return {{"connect", connect},
          {"connect_full_tone_s", connect_full_s},
          {"dots_max_dot_mm", dots_max_mm},
          {"rule", "connect when --time < " + std::to_string(static_cast<int>(kConnectBelow)) +
                       " x connect_full_tone_s or dots_max_dot_mm > " + std::to_string(static_cast<int>(kBlobPens)) +
                       " pen widths (" + std::to_string(kBlobPens * pen_mm).substr(0, 4) +
                       " mm); --connect or --dots chooses"}};
}

// The knob: for the tone law, k in [0, 1/2] lays the share 2k of the tone with the
// largest dots; k in [1/2, 1] lays all of it with the largest dot shrinking
// geometrically from the cap to one pen touch (finer, more dots, more time). For the
// linear law it spreads the paper's radii by up to 20x (k = 1: as given).
class StippleDraft {
 public:
  StippleDraft(const StippleArgs& a, const MethodInput& in) : a_(a), in_(in) {
    tf_ = in.placement.transform(in.image.width, in.image.height);
    pen_ = in.placement.pen_width_mm;
    const double w = in.image.width * tf_.mm_per_px(), h = in.image.height * tf_.mm_per_px();
    // The largest dot: a fortieth of the drawing's short side (a 190 mm wide A4 drawing:
    // 4.75 mm), between four pen widths and 8 mm, or --max-dot.
    if (a.page.law == StippleLaw::Tone && in.placement.dot_size.value > 0)
      throw UserError("--dot-size belongs to --law linear: the tone law sizes its dots for the tone (--max-dot caps them)");
    dot_cap_ = a.max_dot_mm > 0 ? std::max(a.max_dot_mm, pen_) : std::clamp(std::min(w, h) / 40, 4 * pen_, 8.0);
    // Statistics on a grid at half the pen: the area of each level of each pass.
    coarsest_ = std::max(pen_ / 2, in.draft_cell_mm);
    reference_ = std::make_shared<StippleCanvas>(prepare_stipple(in.image, a.m, in.placement, coarsest_));
    canvases_.emplace(coarsest_, reference_);  // a draw at this cell needs no second grid
    const double cell_area = reference_->grid.cell_mm * reference_->grid.cell_mm;
    area_mm2_ = static_cast<double>(reference_->grid.image.pixels()) * cell_area;
    for (const auto& pass : reference_->passes) {
      std::array<double, 256> area{};
      for (uint8_t v : reference_->planes[pass.plane]) area[v] += cell_area;
      double ink = 0;
      for (int v = 0; v < 256; ++v) ink += area[static_cast<size_t>(v)] * pass_tone(pass.ink, v);
      ink_needed_ += ink / area_mm2_;
      level_area_.push_back(area);
    }
    curves_.assign(reference_->passes.size(), CoverageCurve{});
  }

  PageStipple law_at(double k) const {
    PageStipple law = a_.page;
    if (law.law == StippleLaw::Linear) {
      law.spread = std::pow(20.0, 1 - k);
      return law;
    }
    law.fade = std::min(1.0, 2 * k);
    law.pass_curve = curves_;
    law.max_dot_mm = k <= 0.5 ? dot_cap_ : dot_cap_ * std::pow(pen_ / dot_cap_, (k - 0.5) / 0.5);
    if (a_.max_dot_mm > 0) law.max_dot_mm = dot_cap_;
    return law;
  }

  // Grid cells a quarter of the smallest spacing (so the grid's granularity does not
  // pack the dots differently), between an eighth and a half of the pen.
  double cell_at(double k) const {
    const PageStipple law = law_at(k);
    double r_min = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < reference_->passes.size(); ++i) {
      const LevelDots ld = level_dots(*reference_, i, law, tf_.mm_per_px());
      r_min = std::min(r_min, ld.radius.min() * reference_->grid.cell_mm);
    }
    if (!std::isfinite(r_min)) return coarsest_;
    return std::max(std::clamp(r_min / 4, pen_ / 8, pen_ / 2), in_.draft_cell_mm);
  }

  double predict(double k) const {
    const PageStipple law = law_at(k);
    const double cell = cell_at(k);
    double t = 0;
    for (size_t i = 0; i < reference_->passes.size(); ++i)
      t += count_factor_ * pass_cost(i, law, cell).seconds + in_.costs.motion().pen_change_s;
    return t;
  }

  // The pilot: the drawing at k on a grid of twice the cell (a quarter of the cells).
  // What its dots cover at each grey level, against what the law asked for, gives each
  // pass a tone reproduction curve for this photo (grayscale order packs the dots of a
  // gradient closer than the uniform patterns the law was measured on, dots shrink
  // beside highlights, the darkest tones saturate); its dot count against the law's
  // corrects the time prediction.
  void calibrate(double k) {
    if (a_.page.law != StippleLaw::Tone) return;
    const PageStipple law = law_at(k);
    const double cell = std::max(std::min(2 * cell_at(k), pen_), 2 * in_.draft_cell_mm);
    const StippleCanvas pilot = prepare_stipple(in_.image, a_.m, in_.placement, cell);
    const Drawing d = stipple_on_page(pilot, law, tf_.mm_per_px(), a_.seed);
    const bool per_pass = d.layers.size() == pilot.passes.size();
    double drawn = 0, expected = 0;
    for (const auto& l : d.layers) drawn += static_cast<double>(l.dots.size());
    for (size_t i = 0; i < pilot.passes.size(); ++i) expected += pass_cost(i, law, pilot.grid.cell_mm).dots;
    if (expected >= 20) count_factor_ = std::clamp(drawn / expected, 0.5, 3.0);
    if (!per_pass) return;  // colour's 26 layers mix the passes: no curve
    const std::vector<LevelCoverage> got = measured_coverage(pilot, d);
    for (size_t i = 0; i < pilot.passes.size(); ++i) {
      std::vector<double> asked(256), share(256), weight(256);
      for (int v = 0; v < 256; ++v) {
        asked[static_cast<size_t>(v)] = law.fade * pass_tone(pilot.passes[i].ink, v);
        weight[static_cast<size_t>(v)] = got[i].cells[static_cast<size_t>(v)];
        share[static_cast<size_t>(v)] = weight[static_cast<size_t>(v)] > 0 ? got[i].covered[static_cast<size_t>(v)] / weight[static_cast<size_t>(v)] : 0;
      }
      curves_[i] = fit_curve(asked, share, weight);
    }
  }

  MethodResult draw(double k) {
    const PageStipple law = law_at(k);
    const double cell = cell_at(k);
    auto it = canvases_.find(cell);
    if (it == canvases_.end())
      it = canvases_.emplace(cell, std::make_shared<StippleCanvas>(prepare_stipple(in_.image, a_.m, in_.placement, cell))).first;
    const StippleCanvas& canvas = *it->second;
    Progress bar("stippling", 1000, canvas.grid.image.pixels() >= 4'000'000 && in_.show_progress);
    MethodResult r;
    r.drawing = stipple_on_page(canvas, law, tf_.mm_per_px(), a_.seed,
                                [&](double f) { bar.update(static_cast<uint64_t>(f * 1000)); });
    bar.finish();
    r.screen_colours = a_.m == StippleMethod::Color && pens_.empty();
    if (!pens_.empty()) r.drawing = map_layers_to_pens(r.drawing, pens_, true, ink_match());
    size_t dots = 0;
    double dmin = std::numeric_limits<double>::infinity(), dmax = 0;
    for (const auto& l : r.drawing.layers)
      for (const auto& d : l.dots) ++dots, dmin = std::min(dmin, d.diameter), dmax = std::max(dmax, d.diameter);
    r.summary["method"] = to_string(a_.m);
    r.summary["law"] = law.law == StippleLaw::Tone ? "tone" : "linear";
    r.summary["cell_mm"] = canvas.grid.cell_mm;
    r.summary["grid"] = {canvas.grid.image.width, canvas.grid.image.height};
    if (law.law == StippleLaw::Tone) {
      r.summary["max_dot_mm"] = law.max_dot_mm;
      r.summary["fade"] = law.fade;
    } else {
      r.summary["spread"] = law.spread;
    }
    r.summary["dots"] = dots;
    r.summary["style"] = "dots";
    if (!choice_.is_null()) r.summary["style_choice"] = choice_;
    std::ostringstream c;
    c.setf(std::ios::fixed);
    c.precision(2);
    c << dots << " dots";
    if (dots) c << " (" << dmin << "-" << dmax << " mm)";
    c << " in " << layers_phrase(r.drawing.layers.size()) << " (" << to_string(a_.m) << ", " << pixel_size(in_.image) << ")";
    r.counts = c.str();
    return r;
  }

  // Expected dots of pass i under `law` on a grid of `cell` mm, their ink and plot seconds:
  // per level, area x density / spacing^2 dots, each a pen cycle, its fill and a hop of
  // about 1.1 spacings (a greedy tour's step between neighbours).
  struct PassCost {
    double dots = 0, seconds = 0, ink = 0;  // ink: the dots' summed areas, mm^2
  };
  PassCost pass_cost(size_t i, const PageStipple& law, double cell) const {
    const budget::MarkCosts& c = in_.costs;
    const LevelDots ld = level_dots(*reference_, i, law, tf_.mm_per_px());
    PassCost pc;
    for (int v = 0; v < 256; ++v) {
      const double area = level_area_[i][static_cast<size_t>(v)];
      if (ld.radius.none(static_cast<uint8_t>(v)) || area == 0) continue;
      const double r_mm = ld.radius.r[v] * reference_->grid.cell_mm;
      const double dots = area * pattern_density(r_mm / cell) / (r_mm * r_mm);
      pc.dots += dots;
      pc.ink += dots * M_PI / 4 * ld.diameter_mm[static_cast<size_t>(v)] * ld.diameter_mm[static_cast<size_t>(v)];
      pc.seconds += dots * (c.pen_cycle_s() + c.disc_s(ld.diameter_mm[static_cast<size_t>(v)], pen_) + c.travel_s(1.1 * r_mm));
    }
    return pc;
  }

  // The budget chose the dots over the connected drawing (see kConnectBelow).
  void note_choice(nlohmann::json choice) { choice_ = std::move(choice); }
  // The largest dot of the drawing the search would start from at `budget_s` (the
  // prediction before any pilot): how coarse the budget makes the dots. O(100 predictions).
  double predicted_max_dot_mm(double budget_s) const {
    const double k = budget::knob_for(budget::SearchOptions{}.target * budget_s, 1.0, [this](double kk) { return predict(kk); });
    return law_at(k).max_dot_mm;
  }

  // Draw with these pens (the layers' inks mapped to the nearest, see map_layers_to_pens).
  void use_pens(std::vector<Pen> pens) { pens_ = std::move(pens); }
  // cmyk's inks are process colours whose lightness the separation sets: matched by hue.
  InkMatch ink_match() const { return a_.m == StippleMethod::Cmyk ? InkMatch::hue : InkMatch::colour; }

  double tone_share(double k) const { return a_.page.law == StippleLaw::Tone ? std::min(1.0, 2 * k) : 1.0; }
  double ink_needed() const { return ink_needed_; }

 private:
  const StippleArgs& a_;
  const MethodInput& in_;
  PageTransform tf_;
  double pen_ = 0.3, dot_cap_ = 1, area_mm2_ = 0, ink_needed_ = 0;
  std::shared_ptr<StippleCanvas> reference_;
  std::vector<std::array<double, 256>> level_area_;
  std::vector<CoverageCurve> curves_;  // per pass: the pilot's tone reproduction curve
  double count_factor_ = 1;            // the pilot's dots / the law's
  std::map<double, std::shared_ptr<StippleCanvas>> canvases_;
  double coarsest_ = 0;  // the reference grid's cell: half the pen, or a --draft's pixel
  std::vector<Pen> pens_;  // empty: the method's own inks (or screen colours)
  nlohmann::json choice_;  // how the budget chose the dots (null: asked for)
};

// --connect (TSP art). The knob k is the share of the tone laid (points sparser by 1/k
// where the budget is short): k = 1 is the finest drawing, every tone at its line
// spacing. The prediction adds up, per grey level, its points (area x density /
// spacing^2) each drawing a link of the tour (lambda spacings, lambda = kConnectInk /
// density) at the motion model's speed for links of that length turning by about 60
// degrees; a pilot corrects it (see calibrate).
class ConnectDraft {
 public:
  ConnectDraft(const StippleArgs& a, const MethodInput& in) : a_(a), in_(in) {
    tf_ = in.placement.transform(in.image.width, in.image.height);
    pen_ = in.placement.pen_width_mm;
    if (in.placement.dot_size.value > 0) throw UserError("--dot-size belongs to --law linear: --connect draws lines");
    coarsest_ = std::max(pen_ / 2, in.draft_cell_mm);
    reference_ = std::make_shared<StippleCanvas>(prepare_stipple(in.image, a.m, in.placement, coarsest_));
    canvases_.emplace(coarsest_, reference_);  // a draw at this cell needs no second grid
    const double cell_area = reference_->grid.cell_mm * reference_->grid.cell_mm;
    const double area = static_cast<double>(reference_->grid.image.pixels()) * cell_area;
    const auto& pass = reference_->passes.at(0);
    for (uint8_t v : reference_->planes[pass.plane]) level_area_[v] += cell_area;
    for (int v = 0; v < 256; ++v) ink_needed_ += level_area_[static_cast<size_t>(v)] * pass_tone(pass.ink, v) / area;
  }

  ConnectParams params_at(double k) const {
    ConnectParams p;
    p.fade = std::clamp(k, 0.0, 1.0);
    p.curve = curve_.empty() ? nullptr : &curve_;
    p.relax = a_.page.relax;
    p.lift_length = a_.lift_length;
    p.lift_tone = a_.lift_tone;
    p.seed = a_.seed;
    return p;
  }

  // Grid cells a third of the smallest spacing, between a quarter and a half of the pen.
  double cell_at(double k) const {
    const ConnectParams p = params_at(k);
    double r_min = std::numeric_limits<double>::infinity();
    for (int v = 0; v < 256; ++v) r_min = std::min(r_min, connect_spacing_mm(tone(v), pen_, p));
    if (!std::isfinite(r_min)) return coarsest_;
    return std::max(std::clamp(r_min / 2.5, pen_ / 5, pen_ / 2), in_.draft_cell_mm);
  }

  double predict(double k) const { return time_factor_ * raw_seconds(k) + in_.costs.motion().pen_change_s; }

  // The pilot: the drawing at k on a grid of twice the cell. What its line covers at each
  // grey level, against what was asked, gives the tone reproduction curve (lines of
  // neighbouring points overlap in dark tones; a gradient packs points closer); its quick
  // plot estimate against the prediction corrects the time (the tour's real turns, its
  // lifts and their travel).
  void calibrate(double k) {
    const ConnectParams p = params_at(k);
    const double cell = std::max(std::min(2 * cell_at(k), pen_), 2 * in_.draft_cell_mm);
    const StippleCanvas pilot = prepare_stipple(in_.image, a_.m, in_.placement, cell);
    const Drawing d = connect_on_page(pilot, p);
    const double predicted = raw_seconds(k);
    const double t = budget::quick_estimate_seconds(d, in_.costs.motion(), in_.costs.plan_options());
    if (predicted > 1) time_factor_ = std::clamp(t / predicted, 0.3, 5.0);
    const LevelCoverage got = measured_line_coverage(pilot, d);
    std::vector<double> asked(256), share(256), weight(256);
    for (size_t v = 0; v < 256; ++v) {
      const double a = p.fade * tone(static_cast<int>(v));
      asked[v] = a < p.min_coverage ? 0 : a;
      weight[v] = got.cells[v];
      share[v] = weight[v] > 0 ? got.covered[v] / weight[v] : 0;
    }
    curve_ = fit_curve(asked, share, weight);
  }

  MethodResult draw(double k) {
    const ConnectParams p = params_at(k);
    const double cell = cell_at(k);
    auto it = canvases_.find(cell);
    if (it == canvases_.end())
      it = canvases_.emplace(cell, std::make_shared<StippleCanvas>(prepare_stipple(in_.image, a_.m, in_.placement, cell))).first;
    ConnectStats st;
    MethodResult r;
    r.drawing = connect_on_page(*it->second, p, &st);
    r.summary["method"] = to_string(a_.m);
    r.summary["law"] = "tone";
    r.summary["connect"] = {{"points", st.points},      {"lines", st.lines},         {"touches", st.touches},
                            {"links", st.links},        {"lifted", st.lifted},       {"length_m", st.length_mm / 1000},
                            {"lift_length", p.lift_length}, {"lift_tone", p.lift_tone},
                            {"solid_cells", st.solid_cells}, {"hatch_m", st.hatch_mm / 1000}};
    r.summary["fade"] = p.fade;
    r.summary["style"] = "connect";
    if (!choice_.is_null()) r.summary["style_choice"] = choice_;
    r.summary["cell_mm"] = it->second->grid.cell_mm;
    r.summary["grid"] = {it->second->grid.image.width, it->second->grid.image.height};
    std::ostringstream c;
    c.setf(std::ios::fixed);
    c.precision(1);
    c << st.points << " points, drawn as " << st.lines << (st.lines == 1 ? " line" : " lines") << " of "
      << st.length_mm / 1000 << " m";
    if (st.touches) c << " and " << st.touches << " touches";
    if (st.hatch_mm >= 50) c << ", " << st.hatch_mm / 1000 << " m of it hatching solid fields";
    c << " (" << to_string(a_.m) << ", connected, " << pixel_size(in_.image) << ")";
    r.counts = c.str();
    return r;
  }

  double tone_share(double k) const { return std::clamp(k, 0.0, 1.0); }
  // The budget chose the connected drawing (see kConnectBelow).
  void note_choice(nlohmann::json choice) { choice_ = std::move(choice); }
  double ink_needed() const { return ink_needed_; }

 private:
  double tone(int v) const { return pass_tone(reference_->passes[0].ink, v); }

  double raw_seconds(double k) const {
    const ConnectParams p = params_at(k);
    const double cell = cell_at(k);
    double t = 0;
    const double pitch = connect_solid_pitch_mm(pen_, p.fade);
    for (int v = 0; v < 256; ++v) {
      const double area = level_area_[static_cast<size_t>(v)];
      if (area > 0 && p.fade * tone(v) >= p.solid_tone) {  // hatched: long lines near full speed
        t += 1.1 * area / pitch / in_.costs.motion().speed_down_mm_s;
        continue;
      }
      const double r = connect_spacing_mm(tone(v), pen_, p);
      if (area == 0 || !std::isfinite(r)) continue;
      const double density = pattern_density(r / cell);
      const double points = area * density / (r * r);
      t += points * in_.costs.path_link_s(kConnectInk / density * r, 60);
    }
    return t;
  }

  const StippleArgs& a_;
  const MethodInput& in_;
  PageTransform tf_;
  double pen_ = 0.3, ink_needed_ = 0, time_factor_ = 1;
  std::shared_ptr<StippleCanvas> reference_;
  std::array<double, 256> level_area_{};
  CoverageCurve curve_;
  std::map<double, std::shared_ptr<StippleCanvas>> canvases_;
  double coarsest_ = 0;  // the reference grid's cell: half the pen, or a --draft's pixel
  nlohmann::json choice_;  // how the budget chose the connected drawing (null: asked for)
};

// --max-pens: the separation does not depend on the pens, so the small copy is stippled
// once (full tone, the largest dots: the fewest) and each set of pens maps its layers.
PenChoice choose_stipple_pens(const StippleArgs& a, const MethodInput& in) {
  const size_t n = static_cast<size_t>(a.max_pens);
  const SearchInput search = reduced_input(in, greedy_pen_evaluations(a.palette.size(), n));
  const MethodInput small{search.image, search.placement, in.costs, false};
  StippleDraft draft(a, small);
  const Drawing screen = draft.draw(0.5).drawing;
  return choose_pens(a.palette, n, search,
                     [&](const std::vector<Pen>& set) { return map_layers_to_pens(screen, set, true, draft.ink_match()); });
}
}  // namespace

void register_stipple(CLI::App& app) {
  auto args = std::make_shared<StippleArgs>();
  auto m = MethodCommand::add(
      app, "stipple", "Stipple an image with grayscale-order Poisson disk sampling",
      "Methods: gray (dark pixels first; the paper's method), random (random order, for comparison),\n"
      "negative (white dots on black), binary (black and white dots on grey paper),\n"
      "color (binary per R, G, B: the paper's 27-colour screen result), cmyk (ink separation for plotting).\n"
      "color and cmyk take --pens FILE.toml (your pens for their inks) and --max-pens N.\n"
      "Laws: tone (default: dots sized and spaced on the page so the ink lays the photo's tones, as\n"
      "dense as --time allows), linear (the paper's r = a + b d/255; -a/-b with their unit: 3px or 0.2mm).\n"
      "Connected (TSP art): the points joined by one line, pen down, lifted only over light ground;\n"
      "by default the budget draws connected when --time is short for the photo (under twice what the\n"
      "line's whole tone needs, or the dots would be wider than 10 pen widths), dots otherwise;\n"
      "--connect or --dots chooses.\n"
      "Example: stipplot stipple photo.jpg -o photo.svg --preview photo.png --time 45min\n"
      "         stipplot stipple photo.jpg -o photo.svg --connect --preview photo.png\n"
      "         stipplot stipple photo.jpg -o photo.svg --dots --time 4h\n"
      "         stipplot stipple photo.jpg -o photo.svg --law linear -a 3px -b 15px");
  CLI::App* cmd = m->cli();
  const char* g = "Stippling";
  cmd->add_option("-m,--method", args->method, "random|gray|negative|binary|color|cmyk")->capture_default_str();
  auto* law = cmd->add_option("--law", args->law,
                              "tone|linear (tone: dots for the photo's tones on paper; linear: the paper's "
                              "r = a + b d/255, implied by -a, -b, ...)")
                  ->capture_default_str()->group(g);
  cmd->add_option("--max-dot", args->max_dot, "Tone: the largest dot (mm, cm, in, pt); default: chosen for --time")
      ->group(g);
  std::vector<CLI::Option*> linear = {
      cmd->add_option("-a", args->a, "Linear: radius offset a in input pixels (3px) or on paper (0.2mm): r = a + b*d/255")->capture_default_str()->group(g),
      cmd->add_option("-b", args->b, "Linear: radius slope b in input pixels (15px) or on paper (1mm)")->capture_default_str()->group(g),
      cmd->add_option("--a-b", args->a_b, "Linear, binary/colour: black dot radius offset")->capture_default_str()->group(g),
      cmd->add_option("--b-b", args->b_b, "Linear, binary/colour: black dot radius slope")->capture_default_str()->group(g),
      cmd->add_option("--a-w", args->a_w, "Linear, binary/colour: white dot radius offset")->capture_default_str()->group(g),
      cmd->add_option("--b-w", args->b_w, "Linear, binary/colour: white dot radius slope")->capture_default_str()->group(g)};
  cmd->add_option("--relax", args->page.relax,
                  "Tone: Lloyd iterations that even the dots' spacing (weighted Voronoi, as StippleGen); 0 = as sampled")
      ->capture_default_str()->group(g);
  cmd->add_option("--seed", args->seed, "Random seed; the same seed gives the same drawing")->capture_default_str()->group(g);
  cmd->add_option("--pens", args->pens_file,
                  "color, cmyk: TOML palette of your pens; each of the method's inks is drawn with the palette "
                  "pen nearest to it, inks given one pen sharing its layer. cmyk: cyan, magenta and yellow by hue "
                  "(CIEDE2000 at the ink's lightness), black by colour; a palette with no pen within dE00 30 of an "
                  "ink is refused (black.toml: use -m color). color: its 26 screen colours on grey paper by "
                  "CIEDE2000, or the paper where that is nearer (black.toml: a one-pen drawing)")
      ->group("Pens");
  add_max_pens_option(cmd, args->max_pens);
  const char* gc = "Connected (TSP art)";
  cmd->add_flag("--dots", args->dots,
                "Draw the dot stipple whatever --time (default for gray/random/negative with --law tone: the "
                "connected drawing when --time is under twice what its whole tone needs or the dots would be "
                "wider than 10 pen widths, else the dots)")
      ->group(gc);
  cmd->add_flag("--connect", args->connect,
                "Draw connected whatever --time: the points joined by one tour with the pen down (TSP art, Kaplan & Bosch 2005), lifting only "
                "where a link would cross light ground; the points are spaced so the line's ink lays the tone "
                "(-m gray, random, negative; --law tone)")
      ->group(gc);
  std::vector<CLI::Option*> lift = {
      cmd->add_option("--lift-length", args->lift_length,
                      "--connect: lift the pen over links longer than this many local point spacings")
          ->capture_default_str()->group(gc),
      cmd->add_option("--lift-tone", args->lift_tone,
                      "--connect: lift the pen over links whose ground is lighter than this share of their ends' tone "
                      "(0: never for tone)")
          ->capture_default_str()->group(gc)};
  m->define(
      [args, law, linear, lift] {
        args->law_given = law->count() > 0;
        args->lift_given = std::any_of(lift.begin(), lift.end(), [](CLI::Option* o) { return o->count() > 0; });
        args->linear_given = std::any_of(linear.begin(), linear.end(), [](CLI::Option* o) { return o->count() > 0; });
        resolve(*args);
      },
            [args](const MethodInput& in) {
              std::shared_ptr<ConnectDraft> c;
              std::shared_ptr<StippleDraft> d;
              bool connect = args->connect;
              nlohmann::json why;
              if (!args->connect && !args->dots && connectable(*args) && in.budget_s > 0 &&
                  !(in.placement.dot_size.value > 0)) {
                c = std::make_shared<ConnectDraft>(*args, in);
                d = std::make_shared<StippleDraft>(*args, in);
                const double full_tone_s = c->predict(1), max_dot = d->predicted_max_dot_mm(in.budget_s);
                const double pen = in.placement.pen_width_mm;
                connect = in.budget_s < kConnectBelow * full_tone_s || max_dot > kBlobPens * pen;
                why = style_choice(connect, full_tone_s, max_dot, pen);
              }
              if (connect) {
                if (!c) c = std::make_shared<ConnectDraft>(*args, in);
                if (!why.is_null()) c->note_choice(why);
                MethodDraft draft;
                draft.predict = [c](double k) { return c->predict(k); };
                draft.draw = [c](double k) { return c->draw(k); };
                draft.calibrate = [c](double k) { c->calibrate(k); };
                draft.tone_share = [c](double k) { return c->tone_share(k); };
                draft.ink_needed = c->ink_needed();
                return draft;
              }
              if (!d) d = std::make_shared<StippleDraft>(*args, in);
              if (!why.is_null()) d->note_choice(why);
              auto choice = std::make_shared<PenChoice>();
              if (args->max_pens > 0) *choice = choose_stipple_pens(*args, in);
              d->use_pens(args->max_pens > 0 ? choice->pens : args->palette);
              MethodDraft draft;
              draft.predict = [d](double k) { return d->predict(k); };
              draft.draw = [d, choice, n = args->max_pens](double k) {
                MethodResult r = d->draw(k);
                if (n > 0) report_pen_choice(*choice, r);
                return r;
              };
              draft.calibrate = [d](double k) { d->calibrate(k); };
              draft.tone_share = [d](double k) { return d->tone_share(k); };
              draft.ink_needed = d->ink_needed();
              return draft;
            });
}

}  // namespace stipplot::cli
