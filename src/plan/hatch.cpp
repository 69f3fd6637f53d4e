#include "plan/hatch.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "util/error.hpp"

namespace stipplot::plan {

namespace {

constexpr size_t kMaxPoints = 20'000'000;

// An edge of a ring in the frame where hatch lines are horizontal; it holds the lines
// with ylo <= y < yhi (half-open, so a vertex shared by two edges is crossed once).
struct Edge {
  double ylo, yhi, x_at_ylo, dxdy;
  int dir;  // +1 going down (y grows), -1 going up: the winding contribution
};

struct Crossing {
  double x;
  int dir;
};

// A hatch span in the rotated frame, in the order the pen draws it (x0 first).
struct Span {
  double x0, x1;
};

std::vector<Edge> ring_edges(const Area& area, double cs, double sn, double& ymin, double& ymax) {
  std::vector<Edge> edges;
  ymin = INFINITY;
  ymax = -INFINITY;
  for (const auto& ring : area.rings) {
    const auto& p = ring.pts;
    if (p.size() < 3) continue;
    const size_t n = p.front() == p.back() ? p.size() - 1 : p.size();
    for (size_t i = 0; i < n; ++i) {
      const Vec2 a = p[i], b = p[(i + 1) % n];
      const Vec2 ra{a.x * cs + a.y * sn, -a.x * sn + a.y * cs}, rb{b.x * cs + b.y * sn, -b.x * sn + b.y * cs};
      ymin = std::min({ymin, ra.y, rb.y});
      ymax = std::max({ymax, ra.y, rb.y});
      if (ra.y == rb.y) continue;  // horizontal: no line crosses it
      const bool down = rb.y > ra.y;
      const Vec2 lo = down ? ra : rb, hi = down ? rb : ra;
      edges.push_back({lo.y, hi.y, lo.x, (hi.x - lo.x) / (hi.y - lo.y), down ? 1 : -1});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& l, const Edge& r) { return l.ylo < r.ylo; });
  return edges;
}

// The spans of one hatch line inside the area, left to right.
void line_spans(double y, const std::vector<const Edge*>& active, FillRule rule, std::vector<Crossing>& xs,
                std::vector<std::pair<double, double>>& spans) {
  xs.clear();
  for (const Edge* e : active) xs.push_back({e->x_at_ylo + (y - e->ylo) * e->dxdy, e->dir});
  std::sort(xs.begin(), xs.end(), [](const Crossing& l, const Crossing& r) { return l.x < r.x; });
  spans.clear();
  int winding = 0, count = 0;
  bool inside = false;
  double enter = 0;
  for (const Crossing& c : xs) {
    winding += c.dir;
    ++count;
    const bool now = rule == FillRule::evenodd ? (count % 2) != 0 : winding != 0;
    if (now && !inside) enter = c.x;
    if (!now && inside && c.x > enter) spans.push_back({enter, c.x});
    inside = now;
  }
}

// Chains of spans drawn as one stroke: a span joins the chain whose last point, on the
// previous line, lies within `link` of its start, when the short connector between them
// stays inside the area (its midpoint lies in a span of the scanline halfway between).
// Everything here is in the rotated frame; `page` maps back.
class Zigzag {
 public:
  Zigzag(double link, double cs, double sn) : link_(link), cs_(cs), sn_(sn) {}
  void line(double y, const std::vector<Span>& spans, const std::vector<std::pair<double, double>>& between) {
    std::vector<Chain> next;
    std::vector<bool> used(open_.size(), false);
    for (const Span& s : spans) {
      size_t best = open_.size();
      double best_d = link_;
      for (size_t i = 0; i < open_.size(); ++i) {
        if (used[i]) continue;
        const double d = std::hypot(open_[i].x - s.x0, y - open_[i].y);
        const double mid = (open_[i].x + s.x0) / 2;
        const bool inside = std::any_of(between.begin(), between.end(),
                                        [mid](const auto& b) { return mid >= b.first && mid <= b.second; });
        if (d <= best_d && inside) best = i, best_d = d;
      }
      Chain c;
      if (best < open_.size()) {
        used[best] = true;
        c = std::move(open_[best]);
      }
      c.stroke.pts.push_back(page(s.x0, y));
      c.stroke.pts.push_back(page(s.x1, y));
      c.x = s.x1;
      c.y = y;
      points_ += 2;
      next.push_back(std::move(c));
    }
    for (size_t i = 0; i < open_.size(); ++i)
      if (!used[i]) done_.push_back(std::move(open_[i].stroke));
    open_ = std::move(next);
  }
  std::vector<Stroke> finish() {
    for (auto& c : open_) done_.push_back(std::move(c.stroke));
    open_.clear();
    return std::move(done_);
  }
  size_t points() const { return points_; }

 private:
  struct Chain {
    Stroke stroke;
    double x = 0, y = 0;  // its last point, rotated frame
  };
  Vec2 page(double x, double y) const { return {x * cs_ - y * sn_, x * sn_ + y * cs_}; }
  double link_, cs_, sn_;
  size_t points_ = 0;
  std::vector<Chain> open_;
  std::vector<Stroke> done_;
};

}  // namespace

std::vector<Stroke> hatch_area(const Area& area, const HatchOptions& opt) {
  require_range("hatch spacing", opt.spacing_mm, 1e-3, 1000);
  require_range("hatch angle", opt.angle_degrees, -3600, 3600);
  const double th = opt.angle_degrees * std::numbers::pi / 180, cs = std::cos(th), sn = std::sin(th);
  double ymin, ymax;
  const std::vector<Edge> edges = ring_edges(area, cs, sn, ymin, ymax);
  std::vector<Stroke> out;
  if (!edges.empty()) {
    // Lines evenly spread over the height, at most `spacing` apart, the outer ones half a
    // step in from the extremes.
    const double h = ymax - ymin;
    const double lines = std::max(1.0, std::ceil(h / opt.spacing_mm));
    if (lines > static_cast<double>(kMaxPoints))
      throw UserError("a filled shape " + std::to_string(h) + " mm across needs too many hatch lines at spacing " +
                      std::to_string(opt.spacing_mm) + " mm");
    const double step = h / lines;
    Zigzag zig(1.5 * std::max(step, opt.spacing_mm) + 1e-9, cs, sn);
    std::vector<const Edge*> active;
    std::vector<Crossing> xs;
    std::vector<std::pair<double, double>> spans, between;
    std::vector<Span> drawn;
    size_t next_edge = 0;
    // The sweep visits the midlines too (for the connectors' test), so y only grows.
    auto spans_at = [&](double y, std::vector<std::pair<double, double>>& out_spans) {
      while (next_edge < edges.size() && edges[next_edge].ylo <= y) active.push_back(&edges[next_edge++]);
      std::erase_if(active, [y](const Edge* e) { return e->yhi <= y; });
      line_spans(y, active, area.rule, xs, out_spans);
    };
    const auto n_lines = static_cast<size_t>(lines);
    for (size_t k = 0; k < n_lines; ++k) {
      const double y = ymin + (static_cast<double>(k) + 0.5) * step;
      if (k > 0) spans_at(y - step / 2, between);
      spans_at(y, spans);
      // Every other line right to left: a zigzag.
      drawn.clear();
      if (k % 2 == 0) {
        for (const auto& [x0, x1] : spans) drawn.push_back({x0, x1});
      } else {
        for (auto it = spans.rbegin(); it != spans.rend(); ++it) drawn.push_back({it->second, it->first});
      }
      zig.line(y, drawn, between);
      if (zig.points() > kMaxPoints)
        throw UserError("a filled shape needs more than 20 million hatch points at spacing " +
                        std::to_string(opt.spacing_mm) + " mm");
    }
    out = zig.finish();
  }
  if (opt.outline)
    for (const auto& ring : area.rings)
      if (ring.pts.size() >= 2) out.push_back({ring.pts});
  return out;
}

}  // namespace stipplot::plan
