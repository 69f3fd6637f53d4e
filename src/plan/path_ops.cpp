#include "plan/path_ops.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace stipplot::plan {

namespace {

double dist(Vec2 a, Vec2 b) { return std::hypot(a.x - b.x, a.y - b.y); }

// Distance from p to the segment a-b.
double segment_distance(Vec2 p, Vec2 a, Vec2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  if (len2 == 0) return dist(p, a);
  const double t = std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0);
  return dist(p, {a.x + t * dx, a.y + t * dy});
}

}  // namespace

void simplify_stroke(Stroke& s, double tolerance) {
  auto& p = s.pts;
  if (p.size() < 3 || tolerance <= 0) return;
  std::vector<char> keep(p.size(), 0);
  keep.front() = keep.back() = 1;
  // An explicit stack of ranges: deep recursion on long strokes would overflow.
  std::vector<std::pair<size_t, size_t>> todo{{0, p.size() - 1}};
  while (!todo.empty()) {
    const auto [i, j] = todo.back();
    todo.pop_back();
    if (j <= i + 1) continue;
    size_t far = i;
    double far_d = -1;
    // A closed stroke's first and last points coincide: measure from them as a point.
    for (size_t k = i + 1; k < j; ++k) {
      const double d = segment_distance(p[k], p[i], p[j]);
      if (d > far_d) far_d = d, far = k;
    }
    if (far_d > tolerance) {
      keep[far] = 1;
      todo.push_back({i, far});
      todo.push_back({far, j});
    }
  }
  size_t w = 0;
  for (size_t k = 0; k < p.size(); ++k)
    if (keep[k]) p[w++] = p[k];
  p.resize(w);
}

double stroke_length(const Stroke& s) {
  double len = 0;
  for (size_t i = 1; i < s.pts.size(); ++i) len += dist(s.pts[i - 1], s.pts[i]);
  return len;
}

bool is_closed(const Stroke& s) { return s.pts.size() >= 4 && s.pts.front() == s.pts.back(); }

void multipass_stroke(Stroke& s, int passes) {
  if (passes <= 1 || s.pts.size() < 2) return;
  const std::vector<Vec2> once = s.pts;
  const bool closed = is_closed(s);
  s.pts.reserve(once.size() * static_cast<size_t>(passes));
  for (int pass = 1; pass < passes; ++pass) {
    if (closed || pass % 2 == 0) s.pts.insert(s.pts.end(), once.begin() + 1, once.end());
    else s.pts.insert(s.pts.end(), once.rbegin() + 1, once.rend());
  }
}

void reloop_strokes(std::vector<Stroke>& strokes, Vec2 start) {
  Vec2 pos = start;
  for (size_t i = 0; i < strokes.size(); ++i) {
    Stroke& s = strokes[i];
    if (s.pts.empty()) continue;
    if (is_closed(s)) {
      const bool has_next = i + 1 < strokes.size() && !strokes[i + 1].pts.empty();
      const Vec2 next = has_next ? strokes[i + 1].pts.front() : Vec2{};
      const size_t n = s.pts.size() - 1;  // distinct vertices
      size_t best = 0;
      double best_cost = INFINITY;
      for (size_t k = 0; k < n; ++k) {
        const double cost = dist(pos, s.pts[k]) + (has_next ? dist(s.pts[k], next) : 0);
        if (cost < best_cost) best_cost = cost, best = k;
      }
      if (best != 0) {
        std::vector<Vec2> r;
        r.reserve(s.pts.size());
        for (size_t k = 0; k <= n; ++k) r.push_back(s.pts[(best + k) % n]);
        s.pts = std::move(r);
      }
    }
    pos = s.pts.back();
  }
}

}  // namespace stipplot::plan
