#include "cli/pen_choice.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "eval/color_difference.hpp"
#include "eval/fidelity.hpp"
#include "methods/palette.hpp"
#include "methods/working_grid.hpp"
#include "plan/planner.hpp"
#include "preview/preview.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

void add_max_pens_option(CLI::App* cmd, int& max_pens) {
  cmd->add_option("--max-pens", max_pens,
                  "Draw with the N pens of --pens that best reproduce the image (mean CIEDE2000 of the blurred "
                  "pen-true render; greedy, searched on a small copy of the drawing)")
      ->group("Pens");
}

void check_max_pens(int max_pens, size_t palette_size, const std::string& palette_name) {
  if (max_pens == -1) return;  // not given
  if (palette_size == 0) throw UserError("--max-pens chooses among the pens of a palette: give --pens FILE.toml");
  if (max_pens < 1 || static_cast<size_t>(max_pens) > palette_size)
    throw UserError("--max-pens must be between 1 and the " + std::to_string(palette_size) + " pens of " +
                    palette_name + ", got " + std::to_string(max_pens));
}

SearchInput reduced_input(const MethodInput& in, size_t evaluations) {
  // The whole search lays about as many marks as one run: each drawing 1/evaluations of them.
  const double f = std::min(1.0, 1.0 / std::sqrt(static_cast<double>(std::max<size_t>(evaluations, 1))));
  const PageTransform tf = in.placement.transform(in.image.width, in.image.height);
  SearchInput s;
  s.image = f < 1 ? make_working_grid(in.image, tf, tf.mm_per_px() / f).image : in.image;
  s.placement = in.placement;
  s.placement.page.width_mm *= f;
  s.placement.page.height_mm *= f;
  s.placement.margin_mm *= f;
  return s;
}

namespace {
// The pen-true render without planning, when every mark is a disc (dots, filled circles):
// each pen's discs are one filled path, so the pen's ink is their union, multiplied onto
// the page as the plan's render does. Null when some mark is a line or an area.
std::optional<Image> render_discs(const Drawing& d, double dpi) {
  Drawing discs;
  discs.page = d.page;
  for (const Layer& l : d.layers) {
    if (!l.lines.empty() || !l.areas.empty()) return std::nullopt;
    Layer m;
    m.pen = l.pen;
    m.dots = l.dots;
    for (const Circle& c : l.circles) {
      if (!c.filled) return std::nullopt;
      m.dots.push_back(Dot{c.c, 2 * c.r});
    }
    discs.layers.push_back(std::move(m));
  }
  PreviewOptions ro;
  ro.dpi = dpi;
  return render_preview(discs, ro);
}

// The same for marks that are all lines and pen touches: their plan is the strokes as they
// are (the order does not change the render). Null when some mark is wider than the pen.
std::optional<Image> render_strokes(const Drawing& d, double dpi) {
  Plan plan;
  plan.page = d.page;
  for (const Layer& l : d.layers) {
    if (!l.circles.empty() || !l.areas.empty()) return std::nullopt;
    PlannedLayer p;
    p.pen = l.pen;
    for (const Polyline& pl : l.lines)
      if (!pl.pts.empty()) p.strokes.push_back(Stroke{pl.pts});
    for (const Dot& dot : l.dots) {
      if (dot.diameter > l.pen.width_mm) return std::nullopt;
      p.strokes.push_back(Stroke{{dot.c}});
    }
    plan.layers.push_back(std::move(p));
  }
  PreviewOptions ro;
  ro.dpi = dpi;
  return render_plan(plan, ro);
}

double pen_true_error(const Drawing& d, const SearchInput& search) {
  const PageTransform tf = search.placement.transform(search.image.width, search.image.height);
  const double dpi = std::clamp(25.4 / tf.mm_per_px(), 150.0, 600.0);
  const double sigma_px = 1.5 / tf.mm_per_px();
  auto measure = [&](const Image& page) {
    return mean_delta_e00_blurred(search.image, crop_to_image(page, tf, search.image.width, search.image.height), sigma_px);
  };
  if (const auto discs = render_discs(d, dpi)) return measure(*discs);
  if (const auto strokes = render_strokes(d, dpi)) return measure(*strokes);
  PlanOptions po;
  po.optimize_effort = 0;
  po.optimize_seconds = 0;
  // Hatched fills lay the same ink as spirals for the blurred measure, and Cairo strokes
  // their short straight passes several times faster than the spirals' many arcs.
  po.fill = plan::FillMode::Hatch;
  const Plan plan = plan_drawing(d, po);
  PreviewOptions ro;
  ro.dpi = dpi;
  return measure(render_plan(plan, ro));
}
}  // namespace

PenChoice choose_pens(const std::vector<Pen>& palette, size_t n, const SearchInput& search,
                      const std::function<Drawing(const std::vector<Pen>&)>& drawing_for) {
  const auto t0 = std::chrono::steady_clock::now();
  PenChoice out;
  auto pens_of = [&](const std::vector<size_t>& idx) {
    std::vector<Pen> pens;
    for (size_t i : idx) pens.push_back(palette[i]);
    return pens;
  };
  std::map<std::vector<size_t>, double> errors;
  const std::vector<size_t> chosen = choose_pens_greedy(palette.size(), n, [&](const std::vector<size_t>& idx) {
    ++out.evaluations;
    const double e = pen_true_error(drawing_for(pens_of(idx)), search);
    errors[idx] = e;
    return e;
  });
  out.pens = pens_of(chosen);
  out.mean_de00 = errors.count(chosen) ? errors[chosen] : 0;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

void report_pen_choice(const PenChoice& choice, MethodResult& r) {
  nlohmann::json names = nlohmann::json::array();
  std::string list;
  for (const Pen& p : choice.pens) {
    names.push_back(p.name);
    list += (list.empty() ? "" : ", ") + p.name;
  }
  r.summary["max_pens"] = {{"pens", names},
                           {"search_mean_de00", choice.mean_de00},
                           {"evaluations", choice.evaluations},
                           {"seconds", choice.seconds}};
  r.counts += "; pens chosen: " + list;
}

}  // namespace stipplot::cli
