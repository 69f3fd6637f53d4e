#include "plan/planner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <stdexcept>

#include "plan/hatch.hpp"
#include "plan/path_ops.hpp"
#include "plan/tour.hpp"
#include "util/error.hpp"
#include "util/threads.hpp"

namespace stipplot {

void PlanOptions::validate() const {
  require_nonnegative("--optimize-seconds (s)", optimize_seconds);
  require_range("join tolerance (mm)", join_tolerance_mm, 0, 10);
  require_range("fill pitch", fill_pitch, 0.05, 1.0);
  require_range("chord tolerance", chord_tolerance_mm, 1e-4, 1);
  require_range("neighbors", neighbors, 1, 64);
  require_range("origin x", origin.x, -1e6, 1e6);
  require_range("origin y", origin.y, -1e6, 1e6);
  require_range("--optimize-effort", optimize_effort, 0, 1000);
  require_range("--hatch-spacing (mm)", hatch_spacing_mm, 0, 1000);
  require_range("--hatch-angle (degrees)", hatch_angle_degrees, -360, 360);
  require_range("--simplify (mm)", simplify_mm, 0, 100);
  require_range("--min-length (mm)", min_length_mm, 0, 10000);
  require_range("--multipass", passes, 1, 100);
}

namespace {

// Appends make(0) .. make(n - 1) to out in that order, made on every thread when there
// are more than a few hundred (a pointillist's filled discs, each a spiral of sines and
// cosines, come a few thousand a pen).
// The first error any of them throws is thrown. O(n) calls.
template <class Make>
void append_made(std::vector<Stroke>& out, size_t n, const Make& make) {
  constexpr size_t kWorthThreads = 512;
  const size_t first = out.size();
  out.resize(first + n);
  if (n < kWorthThreads || thread_count() < 2 || in_parallel_part()) {
    for (size_t i = 0; i < n; ++i) out[first + i] = make(i);
    return;
  }
  FirstError error;
#pragma omp parallel for schedule(dynamic, 64) num_threads(thread_count())
  for (long i = 0; i < static_cast<long>(n); ++i) {
    if (error.failed()) continue;
    error.capture([&] { out[first + static_cast<size_t>(i)] = make(static_cast<size_t>(i)); });
  }
  error.rethrow();
}

// A layer's primitives as strokes, with the path operations that do not depend on the
// order: joins, simplification and the length filter for polylines, fills, passes.
// `pass`: only the layer's circles of that pass, and its other primitives with pass 0.
void add_layer_strokes(const Layer& layer, const PlanOptions& opt, int pass, std::vector<Stroke>& out) {
  plan::FillOptions fill;
  fill.mode = opt.fill;
  fill.pen_width = layer.pen.width_mm;
  fill.pitch_fraction = opt.fill_pitch;
  fill.chord_tolerance = opt.chord_tolerance_mm;
  const size_t first = out.size();
  // The circles of this pass (or, with pass 0, of no pass).
  auto circles_of = [&](int p) {
    std::vector<const Circle*> of;
    for (const Circle& c : layer.circles)
      if (c.pass == p) of.push_back(&c);
    return of;
  };
  if (pass != 0) {
    const std::vector<const Circle*> circles = circles_of(pass);
    append_made(out, circles.size(), [&](size_t i) { return plan::circle_stroke(*circles[i], fill); });
    if (opt.passes > 1)
      for (size_t i = first; i < out.size(); ++i) plan::multipass_stroke(out[i], opt.passes);
    return;
  }
  for (Stroke& s : plan::join_polylines(layer.lines, opt.join_tolerance_mm)) {
    if (opt.simplify_mm > 0) plan::simplify_stroke(s, opt.simplify_mm);
    if (opt.min_length_mm > 0 && s.pts.size() >= 2 && plan::stroke_length(s) < opt.min_length_mm) continue;
    out.push_back(std::move(s));
  }
  out.reserve(out.size() + layer.dots.size() + layer.circles.size());
  append_made(out, layer.dots.size(), [&](size_t i) {
    const Dot& dot = layer.dots[i];
    if (dot.diameter <= layer.pen.width_mm) return Stroke{{dot.c}};
    return plan::circle_stroke(Circle{dot.c, dot.diameter / 2, true, layer.pen.color}, fill);
  });
  const std::vector<const Circle*> circles = circles_of(0);
  append_made(out, circles.size(), [&](size_t i) { return plan::circle_stroke(*circles[i], fill); });
  plan::HatchOptions hatch;
  hatch.spacing_mm = opt.hatch_spacing_mm > 0 ? opt.hatch_spacing_mm : opt.fill_pitch * layer.pen.width_mm;
  hatch.angle_degrees = opt.hatch_angle_degrees;
  // An area's outline is among the layer's lines already (the reader and the layout's
  // clipping put it there): --fill none leaves only that.
  if (opt.fill != plan::FillMode::None)
    for (const Area& a : layer.areas)
      for (Stroke& s : plan::hatch_area(a, hatch)) out.push_back(std::move(s));
  if (opt.passes > 1)
    for (size_t i = first; i < out.size(); ++i) plan::multipass_stroke(out[i], opt.passes);
}

// The layers each pen draws, in the order pens are first used.
struct PenGroup {
  Pen pen;
  std::vector<const Layer*> layers;
};

std::vector<PenGroup> group_by_pen(const Drawing& d) {
  Drawing numbered;
  numbered.layers.reserve(d.layers.size());
  for (const Layer& l : d.layers) {
    Layer shell;
    shell.pen = l.pen;
    numbered.layers.push_back(std::move(shell));
  }
  resolve_pen_numbers(numbered);  // only the pens: the primitives stay where they are
  std::vector<PenGroup> groups;
  for (size_t i = 0; i < d.layers.size(); ++i) {
    const Pen& pen = numbered.layers[i].pen;
    auto it = std::find_if(groups.begin(), groups.end(), [&](const PenGroup& g) { return g.pen.number == pen.number; });
    if (it == groups.end()) {
      groups.push_back({pen, {}});
      it = groups.end() - 1;
    } else if (it->pen.name != pen.name) {
      it->pen.name += "+" + pen.name;
    }
    it->layers.push_back(&d.layers[i]);
  }
  return groups;
}

// Non-finite coordinates would break the kd-trees' ordering and the fills' loops.
void validate_layer(const Layer& l) {
  // Far-off points would overflow the planner's integer grids (and no sheet is a km wide).
  auto finite = [](Vec2 p) { return std::fabs(p.x) <= kMaxCoordinateMm && std::fabs(p.y) <= kMaxCoordinateMm; };
  if (!(std::isfinite(l.pen.width_mm) && l.pen.width_mm >= 0.01 && l.pen.width_mm <= 100))
    throw UserError("pen '" + l.pen.name + "': width must be between 0.01 and 100 mm");
  for (const Dot& d : l.dots)
    if (!finite(d.c) || !(d.diameter >= 0 && d.diameter <= 1000))
      throw UserError("pen '" + l.pen.name + "': a dot lies outside +-1000000 mm or has a diameter outside 0..1000 mm");
  for (const Polyline& pl : l.lines)
    for (const Vec2& p : pl.pts)
      if (!finite(p)) throw UserError("pen '" + l.pen.name + "': a polyline has a point outside +-1000000 mm (or not a number)");
  for (const Circle& c : l.circles)
    if (!finite(c.c) || !(c.r >= 0 && c.r <= 1000))
      throw UserError("pen '" + l.pen.name + "': a circle has a centre outside +-1000000 mm or a radius outside 0..1000 mm");
  for (const Area& a : l.areas)
    for (const Polyline& ring : a.rings)
      for (const Vec2& p : ring.pts)
        if (!finite(p)) throw UserError("pen '" + l.pen.name + "': a filled shape has a point outside +-1000000 mm (or not a number)");
}

size_t node_count(const Layer& l) {
  size_t rings = 0;
  for (const Area& a : l.areas) rings += a.rings.size();
  return l.dots.size() + l.circles.size() + 2 * l.lines.size() + 2 * rings;
}

// The strokes in tour order from `pos`, each turned the way the tour enters it.
// `share` is this pen's part of the drawing's nodes: its part of the trials and of the cap.
std::vector<Stroke> order_strokes(std::vector<Stroke> strokes, Vec2 pos, const PlanOptions& opt, size_t total_nodes,
                                  double share, PlanInfo& info) {
  // Nodes: a one-point stroke is one node; a longer stroke is two (its ends),
  // partners that the tour keeps adjacent.
  std::vector<Vec2> pts;
  std::vector<int32_t> partner;
  std::vector<uint32_t> stroke_of;
  pts.reserve(2 * strokes.size());
  for (uint32_t i = 0; i < strokes.size(); ++i) {
    const auto& p = strokes[i].pts;
    if (p.size() == 1) {
      pts.push_back(p[0]);
      partner.push_back(-1);
      stroke_of.push_back(i);
    } else {
      const int32_t a = static_cast<int32_t>(pts.size());
      pts.push_back(p.front());
      pts.push_back(p.back());
      partner.push_back(a + 1);
      partner.push_back(a);
      stroke_of.push_back(i);
      stroke_of.push_back(i);
    }
  }
  plan::TourOptions topt;
  topt.neighbors = opt.neighbors;
  // Past the ceiling the trials stop growing with the drawing: there the local optimum
  // alone is within the planner's targets, and trials would cost seconds.
  topt.kicks = std::lround(opt.optimize_effort *
                           std::min(static_cast<double>(total_nodes), PlanOptions::kTrialPointCeiling) * share);
  topt.seconds_cap = opt.optimize_seconds * share;
  plan::TourStats ts;
  const std::vector<uint32_t> order = plan::plan_tour(std::move(pts), partner, pos, topt, &ts);
  info.budget_hit = info.budget_hit || ts.capped;
  info.improving_moves += ts.moves_2opt + ts.moves_oropt;
  std::vector<Stroke> out;
  out.reserve(strokes.size());
  for (size_t k = 0; k < order.size(); ++k) {
    const uint32_t v = order[k];
    Stroke& s = strokes[stroke_of[v]];
    if (partner[v] >= 0) {
      // Entered at node v: v is the stroke's start if it is the first of the pair.
      const bool reversed = static_cast<uint32_t>(partner[v]) < v;
      if (reversed) std::reverse(s.pts.begin(), s.pts.end());
      if (k + 1 >= order.size() || order[k + 1] != static_cast<uint32_t>(partner[v]))
        throw std::logic_error("plan_tour separated a stroke's ends");
      ++k;  // the partner follows
    }
    out.push_back(std::move(s));
  }
  return out;
}

// `owned`: the same drawing as `d`, the caller's to give up (its primitives are cleared
// as the strokes take them), or null.
Plan plan_layers(const Drawing& d, const PlanOptions& opt, PlanInfo* info, Drawing* owned) {
  const auto t0 = std::chrono::steady_clock::now();
  PlanInfo local;
  opt.validate();
  if (!(d.layers.size() < 100000)) throw UserError("drawing has too many layers");
  Plan plan;
  plan.page = d.page;
  size_t total_nodes = 0;
  for (const Layer& l : d.layers) {
    validate_layer(l);
    total_nodes += node_count(l);
  }
  Vec2 pos = opt.origin;
  for (const PenGroup& group : group_by_pen(d)) {
    PlannedLayer out;
    out.pen = group.pen;
    // Each pass of the pen's circles is one tour, from where the previous one ended.
    std::set<int> passes{0};
    for (const Layer* layer : group.layers)
      for (const Circle& c : layer->circles) passes.insert(c.pass);
    for (const int pass : passes) {
      std::vector<Stroke> strokes;
      size_t nodes = 0;
      for (const Layer* layer : group.layers) {
        add_layer_strokes(*layer, opt, pass, strokes);
        nodes += passes.size() == 1 ? node_count(*layer) : 0;
      }
      if (owned && passes.size() == 1)
        for (const Layer* layer : group.layers) {
          Layer& l = owned->layers[static_cast<size_t>(layer - d.layers.data())];
          l.dots = {}, l.lines = {}, l.circles = {}, l.areas = {};
        }
      if (passes.size() > 1) nodes = strokes.size();
      const double share = total_nodes == 0 ? 0 : static_cast<double>(nodes) / total_nodes;
      std::vector<Stroke> ordered = order_strokes(std::move(strokes), pos, opt, total_nodes, share, local);
      if (opt.reloop) plan::reloop_strokes(ordered, pos);
      if (!ordered.empty()) pos = ordered.back().pts.back();
      if (out.strokes.empty()) out.strokes = std::move(ordered);  // no second array of a million strokes
      else out.strokes.insert(out.strokes.end(), std::make_move_iterator(ordered.begin()),
                              std::make_move_iterator(ordered.end()));
    }
    plan.layers.push_back(std::move(out));
  }
  local.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (info) *info = local;
  return plan;
}

}  // namespace

Plan plan_drawing(const Drawing& d, const PlanOptions& opt) { return plan_layers(d, opt, nullptr, nullptr); }

Plan plan_drawing(const Drawing& d, const PlanOptions& opt, PlanInfo* info) { return plan_layers(d, opt, info, nullptr); }

Plan plan_drawing(Drawing&& d, const PlanOptions& opt, PlanInfo* info) { return plan_layers(d, opt, info, &d); }

double pen_up_travel(const Plan& plan, Vec2 pos) {
  double s = 0;
  for (const auto& l : plan.layers)
    for (const auto& st : l.strokes) {
      if (st.pts.empty()) continue;
      s += std::hypot(st.pts.front().x - pos.x, st.pts.front().y - pos.y);
      pos = st.pts.back();
    }
  return s;
}

}  // namespace stipplot
