#include "methods/sketch/link.hpp"

#include <algorithm>
#include <cmath>
#include <exception>

#include "methods/link_rule.hpp"
#include "plan/tour.hpp"
#include "util/error.hpp"
#include "util/threads.hpp"

namespace stipplot::sketch {

void LinkParams::validate() const {
  require_range("--link-length", lift_length, 0, 1e3);
  require_range("--link-tone", lift_tone, 0, 1e3);
}

namespace {
// One pen's probability field on the page.
struct Field {
  const SketchResult& r;
  const std::vector<float>& p;
  double density;
  float at(Vec2 q) const {
    const int x = std::clamp(static_cast<int>((q.x - r.grid_origin_mm.x) / r.cell_w_mm), 0, r.grid_w - 1);
    const int y = std::clamp(static_cast<int>((q.y - r.grid_origin_mm.y) / r.cell_h_mm), 0, r.grid_h - 1);
    return p[static_cast<size_t>(y) * static_cast<size_t>(r.grid_w) + static_cast<size_t>(x)];
  }
  // Mean distance between the kept marks near q, in mm.
  double spacing(Vec2 q) const {
    const double marks = -std::log1p(-std::min(0.999, static_cast<double>(at(q)))) * density;
    return std::sqrt(r.cell_w_mm * r.cell_h_mm / std::max(marks, 1e-6));
  }
};

bool lifted(const Field& f, const LinkParams& p, double cell_mm, Vec2 a, Vec2 b) {
  if (!(f.at(a) + f.at(b) > 0)) return true;  // both ends on ground this pen is not for
  return link_lifted(a, b, std::max(f.spacing(a), f.spacing(b)), cell_mm, p.lift_length, p.lift_tone,
                     [&](Vec2 q) { return f.at(q); });  // float, as the grid holds it
}

Layer link_layer(const Field& f, const Layer& in, const LinkParams& p, LinkStats& st) {
  Layer out;
  out.pen = in.pen;
  out.dots = in.dots;
  out.circles = in.circles;
  out.areas = in.areas;
  std::vector<const Polyline*> strokes;
  for (const Polyline& l : in.lines)
    if (!l.pts.empty()) strokes.push_back(&l);
  st.strokes += strokes.size();
  if (strokes.empty()) return out;
  std::vector<Vec2> ends;
  std::vector<int32_t> partner;
  ends.reserve(2 * strokes.size());
  for (size_t i = 0; i < strokes.size(); ++i) {
    ends.push_back(strokes[i]->pts.front());
    ends.push_back(strokes[i]->pts.back());
    partner.push_back(static_cast<int32_t>(2 * i + 1));
    partner.push_back(static_cast<int32_t>(2 * i));
  }
  plan::TourOptions to;
  to.seconds_cap = p.tour_seconds_cap;
  to.seed = p.seed;
  const std::vector<uint32_t> path = plan::plan_tour(ends, partner, {0, 0}, to);
  const double cell = std::min(f.r.cell_w_mm, f.r.cell_h_mm);
  Polyline run;
  for (size_t i = 0; i + 1 < path.size(); i += 2) {
    // path[i] enters stroke path[i] / 2 and path[i + 1] leaves it.
    const Polyline& s = *strokes[path[i] / 2];
    const bool reversed = path[i] % 2 == 1;
    if (!run.pts.empty()) {
      const Vec2 a = run.pts.back(), b = reversed ? s.pts.back() : s.pts.front();
      if (lifted(f, p, cell, a, b)) {
        out.lines.push_back(std::move(run));
        run = Polyline{};
      } else {
        ++st.links;
        st.link_mm += std::hypot(b.x - a.x, b.y - a.y);
      }
    }
    if (reversed)
      run.pts.insert(run.pts.end(), s.pts.rbegin(), s.pts.rend());
    else
      run.pts.insert(run.pts.end(), s.pts.begin(), s.pts.end());
  }
  if (!run.pts.empty()) out.lines.push_back(std::move(run));
  st.lines += out.lines.size();
  return out;
}
}  // namespace

Drawing link_strokes(const SketchResult& r, const Drawing& kept, double density, const LinkParams& p, LinkStats* stats) {
  p.validate();
  if (!(density > 0 && density <= 1)) throw UserError("link_strokes: density must be in (0, 1]");
  // Each pen's strokes are linked by a tour of their own: the pens side by side (the
  // largest first), their layers and counts put together in layer order, so the drawing
  // is the same on any thread count.
  const size_t n = kept.layers.size();
  Drawing out;
  out.page = kept.page;
  out.layers.resize(n);
  std::vector<LinkStats> per(n);
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return kept.layers[a].lines.size() > kept.layers[b].lines.size(); });
  std::vector<std::exception_ptr> failed(n);
#pragma omp parallel for schedule(dynamic, 1) num_threads(thread_count()) if (n > 1)
  for (long k = 0; k < static_cast<long>(n); ++k) {
    const size_t i = order[static_cast<size_t>(k)];
    const Layer& l = kept.layers[i];
    try {
      const auto it = std::find_if(r.pens.begin(), r.pens.end(), [&](const PenStrokes& ps) {
        return ps.pen.name == l.pen.name && ps.pen.color == l.pen.color;
      });
      if (it == r.pens.end() || r.prob.size() != r.pens.size()) {
        out.layers[i] = l;
        continue;
      }
      const Field f{r, r.prob[static_cast<size_t>(it - r.pens.begin())], density};
      out.layers[i] = link_layer(f, l, p, per[i]);
    } catch (...) {
      failed[i] = std::current_exception();  // an exception must not leave an OpenMP region
    }
  }
  for (const auto& e : failed)
    if (e) std::rethrow_exception(e);
  LinkStats st;
  for (const LinkStats& s : per) {
    st.strokes += s.strokes;
    st.lines += s.lines;
    st.links += s.links;
    st.link_mm += s.link_mm;
  }
  if (stats) *stats = st;
  return out;
}

}  // namespace stipplot::sketch
