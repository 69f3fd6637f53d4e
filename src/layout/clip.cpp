#include "layout/clip.hpp"

#include <algorithm>
#include <cmath>

#include "geometry/shapes.hpp"

namespace stipplot::layout {

namespace {

// Points this close outside still count as on the sheet: rounding after a rotation or a
// fit must not cut a stroke that touches the edge.
constexpr double kSlack = 1e-7;

// Points within kSlack outside the edge are moved onto it, so the cut is exact.
double snap(double v, double lo, double hi) {
  if (v < lo && v > lo - kSlack) return lo;
  if (v > hi && v < hi + kSlack) return hi;
  return v;
}
void snap_points(std::vector<Vec2>& pts, const Rect& r) {
  for (Vec2& p : pts) p = {snap(p.x, r.x0, r.x1), snap(p.y, r.y0, r.y1)};
}

// Liang-Barsky: the part of segment p->q inside r as parameters [t0, t1]; false if none.
bool clip_segment(Vec2 p, Vec2 q, const Rect& r, double& t0, double& t1) {
  t0 = 0;
  t1 = 1;
  const double dx = q.x - p.x, dy = q.y - p.y;
  const double ps[4] = {-dx, dx, -dy, dy};
  const double qs[4] = {p.x - r.x0, r.x1 - p.x, p.y - r.y0, r.y1 - p.y};
  for (int i = 0; i < 4; ++i) {
    if (ps[i] == 0) {
      if (qs[i] < 0) return false;
      continue;
    }
    const double t = qs[i] / ps[i];
    if (ps[i] < 0) t0 = std::max(t0, t);
    else t1 = std::min(t1, t);
    if (t0 > t1) return false;
  }
  return true;
}

Vec2 lerp(Vec2 p, Vec2 q, double t) { return {p.x + (q.x - p.x) * t, p.y + (q.y - p.y) * t}; }

// The runs of a polyline inside r; a closed polyline whose seam lies inside and that is
// cut elsewhere has its last run joined to its first, so it stays one stroke.
std::vector<Polyline> clip_polyline(const Polyline& pl, const Rect& r, bool& changed) {
  std::vector<Polyline> runs;
  const auto& p = pl.pts;
  changed = false;
  if (p.size() == 1) {
    if (r.contains(p[0])) runs.push_back(pl);
    else changed = true;
    return runs;
  }
  Polyline cur;
  for (size_t i = 0; i + 1 < p.size(); ++i) {
    double t0, t1;
    if (!clip_segment(p[i], p[i + 1], r, t0, t1)) {
      changed = true;
      if (cur.pts.size() >= 2) runs.push_back(std::move(cur));
      cur = {};
      continue;
    }
    if (t0 > 0 || cur.pts.empty()) {
      if (t0 > 0) changed = true;
      if (cur.pts.size() >= 2) runs.push_back(std::move(cur));
      cur = {};
      cur.pts.push_back(t0 > 0 ? lerp(p[i], p[i + 1], t0) : p[i]);
    }
    cur.pts.push_back(t1 < 1 ? lerp(p[i], p[i + 1], t1) : p[i + 1]);
    if (t1 < 1) {
      changed = true;
      if (cur.pts.size() >= 2) runs.push_back(std::move(cur));
      cur = {};
    }
  }
  if (cur.pts.size() >= 2) runs.push_back(std::move(cur));
  const bool closed = p.size() >= 3 && p.front() == p.back();
  if (closed && changed && runs.size() >= 2 && runs.front().pts.front() == p.front() && runs.back().pts.back() == p.back()) {
    Polyline& last = runs.back();
    last.pts.insert(last.pts.end(), runs.front().pts.begin() + 1, runs.front().pts.end());
    runs.front() = std::move(last);
    runs.pop_back();
  }
  return runs;
}

// Sutherland-Hodgman against one edge of the window: keep where inside(p) holds.
template <class Inside, class Cross>
std::vector<Vec2> clip_ring_edge(const std::vector<Vec2>& in, Inside inside, Cross cross) {
  std::vector<Vec2> out;
  if (in.empty()) return out;
  out.reserve(in.size() + 4);
  for (size_t i = 0; i < in.size(); ++i) {
    const Vec2 a = in[i], b = in[(i + 1) % in.size()];
    const bool ia = inside(a), ib = inside(b);
    if (ia) out.push_back(a);
    if (ia != ib) out.push_back(cross(a, b));
  }
  return out;
}

// A ring clipped to r (closed: first point repeated); empty when nothing is left.
std::vector<Vec2> clip_ring(const std::vector<Vec2>& ring, const Rect& r) {
  std::vector<Vec2> v(ring.begin(), ring.end());
  if (v.size() >= 2 && v.front() == v.back()) v.pop_back();
  auto at_x = [](Vec2 a, Vec2 b, double x) { return Vec2{x, a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x)}; };
  auto at_y = [](Vec2 a, Vec2 b, double y) { return Vec2{a.x + (b.x - a.x) * (y - a.y) / (b.y - a.y), y}; };
  v = clip_ring_edge(v, [&](Vec2 p) { return p.x >= r.x0; }, [&](Vec2 a, Vec2 b) { return at_x(a, b, r.x0); });
  v = clip_ring_edge(v, [&](Vec2 p) { return p.x <= r.x1; }, [&](Vec2 a, Vec2 b) { return at_x(a, b, r.x1); });
  v = clip_ring_edge(v, [&](Vec2 p) { return p.y >= r.y0; }, [&](Vec2 a, Vec2 b) { return at_y(a, b, r.y0); });
  v = clip_ring_edge(v, [&](Vec2 p) { return p.y <= r.y1; }, [&](Vec2 a, Vec2 b) { return at_y(a, b, r.y1); });
  if (v.size() < 3) return {};
  v.push_back(v.front());
  return v;
}

bool ring_inside(const std::vector<Vec2>& ring, const Rect& r) {
  for (const Vec2& p : ring)
    if (!r.contains(p)) return false;
  return true;
}

// Rings clipped; false if the area vanished. `changed` says whether any ring was cut.
bool clip_area(Area& a, const Rect& r, bool& changed) {
  changed = false;
  std::vector<Polyline> kept;
  for (auto& ring : a.rings) {
    if (ring_inside(ring.pts, r)) {
      kept.push_back(std::move(ring));
      continue;
    }
    changed = true;
    std::vector<Vec2> c = clip_ring(ring.pts, r);
    if (!c.empty()) kept.push_back({std::move(c)});
  }
  a.rings = std::move(kept);
  return !a.rings.empty();
}

enum class DiscPlace { inside, outside, crossing };
DiscPlace place_disc(Vec2 c, double rad, const Rect& exact) {
  const Rect r{exact.x0 - kSlack, exact.y0 - kSlack, exact.x1 + kSlack, exact.y1 + kSlack};
  if (c.x - rad >= r.x0 && c.x + rad <= r.x1 && c.y - rad >= r.y0 && c.y + rad <= r.y1) return DiscPlace::inside;
  const double nx = std::clamp(c.x, r.x0, r.x1), ny = std::clamp(c.y, r.y0, r.y1);
  if (std::hypot(c.x - nx, c.y - ny) >= rad) return DiscPlace::outside;
  return DiscPlace::crossing;
}

// A filled disc that crosses the edge, as a clipped area and the part of its outline on
// the sheet; false if nothing is left.
bool disc_area(Vec2 c, double rad, Color fill, const Rect& r, double tol, std::vector<Area>& out,
               std::vector<Polyline>& outline, bool with_rim) {
  Area a;
  a.fill = fill;
  a.rings.push_back({circle_points(c, rad, tol)});
  bool changed;
  // The cut rim as a line in the layer's pen: only when the pen is the disc's colour
  // (a disc in its own exact colour would get a rim of another ink).
  std::vector<Polyline> rim = clip_polyline(a.rings.front(), r, changed);
  if (with_rim)
    for (auto& run : rim) outline.push_back(std::move(run));
  if (!clip_area(a, r, changed)) return false;
  out.push_back(std::move(a));
  return true;
}

ClipCounts clip_layer(Layer& l, const Rect& r, double tol) {
  ClipCounts n;
  std::vector<Polyline> lines;
  for (auto& pl : l.lines) {
    snap_points(pl.pts, r);
    // Wholly on the sheet, the common case: kept as it is (clipping would return the same
    // points, copied one by one: a tree's 433,000-point outline).
    if (pl.pts.size() >= 2 && std::all_of(pl.pts.begin(), pl.pts.end(), [&](Vec2 p) { return r.contains(p); })) {
      lines.push_back(std::move(pl));
      continue;
    }
    bool changed;
    auto runs = clip_polyline(pl, r, changed);
    if (runs.empty()) ++n.dropped;
    else if (changed) ++n.cut;
    for (auto& run : runs) lines.push_back(std::move(run));
  }
  std::vector<Area> areas;
  for (auto& a : l.areas) {
    for (auto& ring : a.rings) snap_points(ring.pts, r);
    bool changed;
    if (!clip_area(a, r, changed)) {
      ++n.dropped;
      continue;
    }
    if (changed) ++n.cut;
    areas.push_back(std::move(a));
  }
  std::vector<Dot> dots;
  for (const auto& d : l.dots) {
    const DiscPlace at = place_disc(d.c, d.diameter / 2, r);
    if (at == DiscPlace::inside) dots.push_back(d);
    else if (at == DiscPlace::outside) ++n.dropped;
    else if (d.diameter <= l.pen.width_mm) r.contains(d.c) ? dots.push_back(d) : void(++n.dropped);  // a touch
    else disc_area(d.c, d.diameter / 2, l.pen.color, r, tol, areas, lines, true) ? void(++n.cut) : void(++n.dropped);
  }
  std::vector<Circle> circles;
  for (const auto& c : l.circles) {
    const DiscPlace at = place_disc(c.c, c.r, r);
    if (at == DiscPlace::inside) {
      circles.push_back(c);
    } else if (at == DiscPlace::outside) {
      ++n.dropped;
    } else if (c.filled) {
      disc_area(c.c, c.r, c.fill, r, tol, areas, lines, c.fill == l.pen.color) ? void(++n.cut) : void(++n.dropped);
    } else {
      bool changed;
      auto runs = clip_polyline({circle_points(c.c, c.r, tol)}, r, changed);
      runs.empty() ? void(++n.dropped) : void(++n.cut);
      for (auto& run : runs) lines.push_back(std::move(run));
    }
  }
  l.lines = std::move(lines);
  l.areas = std::move(areas);
  l.dots = std::move(dots);
  l.circles = std::move(circles);
  return n;
}

}  // namespace

ClipCounts clip_to_rect(Drawing& d, const Rect& r, double chord_tolerance) {
  ClipCounts n;
  for (auto& l : d.layers) n += clip_layer(l, r, chord_tolerance);
  return n;
}

}  // namespace stipplot::layout
