#include "plan/planner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "plan/tour.hpp"
#include "util/error.hpp"

namespace stipplot {

void PlanOptions::validate() const {
  require_nonnegative("--optimize-seconds", optimize_seconds);
  require_range("--optimize-effort", optimize_effort, 0, 1000);
  require_range("join tolerance", join_tolerance_mm, 0, 10);
  require_range("fill pitch", fill_pitch, 0.05, 1.0);
  require_range("chord tolerance", chord_tolerance_mm, 1e-4, 1);
  require_range("neighbors", neighbors, 1, 64);
  require_range("origin x", origin.x, -1e6, 1e6);
  require_range("origin y", origin.y, -1e6, 1e6);
}

namespace {

std::vector<Stroke> layer_strokes(const Layer& layer, const PlanOptions& opt) {
  plan::FillOptions fill;
  fill.mode = opt.fill;
  fill.pen_width = layer.pen.width_mm;
  fill.pitch_fraction = opt.fill_pitch;
  fill.chord_tolerance = opt.chord_tolerance_mm;
  std::vector<Stroke> out = plan::join_polylines(layer.lines, opt.join_tolerance_mm);
  out.reserve(out.size() + layer.dots.size() + layer.circles.size());
  for (const Dot& dot : layer.dots) {
    if (dot.diameter <= layer.pen.width_mm) {
      out.push_back({{dot.c}});
    } else {
      out.push_back(plan::circle_stroke(Circle{dot.c, dot.diameter / 2, true, layer.pen.color}, fill));
    }
  }
  for (const Circle& c : layer.circles) out.push_back(plan::circle_stroke(c, fill));
  return out;
}

// Non-finite coordinates would break the kd-trees' ordering and the fills' loops.
void validate_layer(const Layer& l) {
  auto finite = [](Vec2 p) { return std::isfinite(p.x) && std::isfinite(p.y); };
  if (!(std::isfinite(l.pen.width_mm) && l.pen.width_mm >= 0.01 && l.pen.width_mm <= 100))
    throw UserError("pen '" + l.pen.name + "': width must be between 0.01 and 100 mm");
  for (const Dot& d : l.dots)
    if (!finite(d.c) || !(d.diameter >= 0 && d.diameter <= 1000))
      throw UserError("pen '" + l.pen.name + "': a dot has a non-finite position or a diameter outside 0..1000 mm");
  for (const Polyline& pl : l.lines)
    for (const Vec2& p : pl.pts)
      if (!finite(p)) throw UserError("pen '" + l.pen.name + "': a polyline has a non-finite point");
  for (const Circle& c : l.circles)
    if (!finite(c.c) || !(c.r >= 0 && c.r <= 1000))
      throw UserError("pen '" + l.pen.name + "': a circle has a non-finite centre or a radius outside 0..1000 mm");
}

size_t node_count(const Layer& l) { return l.dots.size() + l.circles.size() + 2 * l.lines.size(); }

}  // namespace

Plan plan_drawing(const Drawing& d, const PlanOptions& opt) { return plan_drawing(d, opt, nullptr); }

Plan plan_drawing(const Drawing& d, const PlanOptions& opt, PlanInfo* info) {
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
  for (const Layer& layer : d.layers) {
    PlannedLayer out;
    out.pen = layer.pen;
    std::vector<Stroke> strokes = layer_strokes(layer, opt);
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
    const double share = total_nodes == 0 ? 0 : static_cast<double>(node_count(layer)) / total_nodes;
    // Past the ceiling the trials stop growing with the drawing: there the local optimum
    // alone is within the planner's targets, and trials would cost seconds.
    topt.kicks = std::lround(opt.optimize_effort *
                             std::min(static_cast<double>(total_nodes), PlanOptions::kTrialPointCeiling) * share);
    topt.seconds_cap = opt.optimize_seconds * share;
    plan::TourStats ts;
    const std::vector<uint32_t> order = plan::plan_tour(pts, partner, pos, topt, &ts);
    local.budget_hit = local.budget_hit || ts.capped;
    local.improving_moves += ts.moves_2opt + ts.moves_oropt;
    out.strokes.reserve(strokes.size());
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
      out.strokes.push_back(std::move(s));
    }
    if (!out.strokes.empty()) pos = out.strokes.back().pts.back();
    plan.layers.push_back(std::move(out));
  }
  local.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (info) *info = local;
  return plan;
}

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
