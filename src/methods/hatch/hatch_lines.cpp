#include "methods/hatch/hatch_lines.hpp"

#include <algorithm>
#include <cmath>

#include "util/threads.hpp"

namespace stipplot::hatch {

bool Mask::inside(double cx, double cy) const {
  if (!(cx >= 0 && cy >= 0)) return false;
  const int x = static_cast<int>(cx), y = static_cast<int>(cy);
  return x < width && y < height && in[static_cast<size_t>(y) * width + x] != 0;
}

namespace {
constexpr double kStep = 0.5;    // sampling step along a line, cells
constexpr double kMinRun = 1.5;  // shorter runs are specks a pen would only dot (cells)

struct Run {
  double a0, a1;  // along the line, a0 < a1
};

// A line's frame: points are a * u + t * n.
struct Frame {
  Vec2 u, n;
  Vec2 at(double a, double t) const { return {a * u.x + t * n.x, a * u.y + t * n.y}; }
};

// The inside stretches of the line at offset t, sampled from a_lo to a_hi; runs shorter
// than kMinRun are left out.
std::vector<Run> runs_on_line(const Mask& m, const Frame& f, double t, double a_lo, double a_hi) {
  std::vector<Run> runs;
  bool open = false;
  double start = 0, last = 0;
  for (double a = a_lo; a <= a_hi; a += kStep) {
    const Vec2 p = f.at(a, t);
    if (m.inside(p.x, p.y)) {
      if (!open) open = true, start = a;
      last = a;
    } else if (open) {
      open = false;
      if (last - start >= kMinRun) runs.push_back({start, last});
    }
  }
  if (open && last - start >= kMinRun) runs.push_back({start, last});
  return runs;
}

// Inside, or a cell's side from a cell that is: a region's edge on the grid is a
// staircase, which a straight link along it clips at its corners.
bool near_inside(const Mask& m, double x, double y) {
  return m.inside(x, y) || m.inside(x - 1, y) || m.inside(x + 1, y) || m.inside(x, y - 1) || m.inside(x, y + 1);
}

// True when the straight link from p to q stays inside, up to a cell (sampled every half cell).
bool link_inside(const Mask& m, Vec2 p, Vec2 q) {
  const double len = std::hypot(q.x - p.x, q.y - p.y);
  const int steps = std::max(1, static_cast<int>(std::ceil(len / kStep)));
  for (int i = 1; i < steps; ++i) {
    const double s = static_cast<double>(i) / steps;
    if (!near_inside(m, p.x + s * (q.x - p.x), p.y + s * (q.y - p.y))) return false;
  }
  return true;
}

struct Chain {
  std::vector<Vec2> pts;
  bool forward = true;  // its last run was drawn towards larger a
  double end_a = 0;     // where on its last line it ended
};

// Appends run r of the line at t to chain c, entered from the end its direction gives.
void extend(Chain& c, const Frame& f, const Run& r, double t, bool forward) {
  c.pts.push_back(f.at(forward ? r.a0 : r.a1, t));
  c.pts.push_back(f.at(forward ? r.a1 : r.a0, t));
  c.forward = forward;
  c.end_a = forward ? r.a1 : r.a0;
}
}  // namespace

std::vector<std::vector<Vec2>> hatch_mask(const Mask& m, const LineSet& s) {
  std::vector<std::vector<Vec2>> out;
  if (m.width <= 0 || m.height <= 0 || !(s.spacing > 0)) return out;
  const double th = s.angle_deg * M_PI / 180;
  const Frame f{{std::cos(th), -std::sin(th)}, {std::sin(th), std::cos(th)}};
  // The grid's extent along and across the lines.
  double a_lo = 1e300, a_hi = -1e300, t_lo = 1e300, t_hi = -1e300;
  for (Vec2 c : {Vec2{0, 0}, Vec2{double(m.width), 0}, Vec2{0, double(m.height)}, Vec2{double(m.width), double(m.height)}}) {
    const double a = c.x * f.u.x + c.y * f.u.y, t = c.x * f.n.x + c.y * f.n.y;
    a_lo = std::min(a_lo, a), a_hi = std::max(a_hi, a), t_lo = std::min(t_lo, t), t_hi = std::max(t_hi, t);
  }
  // Samples on a fixed lattice along the line (multiples of the step), so neighbouring
  // lines' run ends line up.
  a_lo = std::floor(a_lo / kStep) * kStep + 0.25;
  std::vector<Chain> open;  // chains ending on the previous line, in the order of their runs
  const long i0 = static_cast<long>(std::ceil(t_lo / s.spacing - 0.5));
  const long i1 = static_cast<long>(std::floor(t_hi / s.spacing - 0.5));
  // Each line's runs on every thread (each line sampled as one pass would), then linked
  // line by line in order.
  const long lines = std::max(0L, i1 - i0 + 1);
  std::vector<std::vector<Run>> line_runs(static_cast<size_t>(lines));
  const double samples = static_cast<double>(lines) * (a_hi - a_lo) / kStep;
  const bool threads = samples > 200'000 && thread_count() > 1 && !in_parallel_part();
#pragma omp parallel for schedule(dynamic, 8) num_threads(thread_count()) if (threads)
  for (long i = i0; i <= i1; ++i)
    line_runs[static_cast<size_t>(i - i0)] = runs_on_line(m, f, (static_cast<double>(i) + 0.5) * s.spacing, a_lo, a_hi);
  for (long i = i0; i <= i1; ++i) {
    const double t = (static_cast<double>(i) + 0.5) * s.spacing;
    const std::vector<Run> runs = std::move(line_runs[static_cast<size_t>(i - i0)]);
    std::vector<double> ends(open.size());
    for (size_t k = 0; k < open.size(); ++k) ends[k] = open[k].end_a;  // sorted: runs are disjoint
    std::vector<uint8_t> taken(open.size(), 0);
    std::vector<Chain> next;
    next.reserve(runs.size());
    for (const Run& r : runs) {
      // The open chain with the shortest link into r that stays inside.
      long best = -1;
      double best_len = s.link;
      for (size_t k = static_cast<size_t>(std::lower_bound(ends.begin(), ends.end(), r.a0 - s.link) - ends.begin());
           k < open.size() && ends[k] <= r.a1 + s.link; ++k) {
        if (taken[k]) continue;
        const double entry = open[k].forward ? r.a1 : r.a0;  // zig-zag: the next run runs back
        const double len = std::hypot(entry - ends[k], s.spacing);
        if (len <= best_len && link_inside(m, open[k].pts.back(), f.at(entry, t))) best = static_cast<long>(k), best_len = len;
      }
      if (best >= 0) {
        taken[static_cast<size_t>(best)] = 1;
        Chain c = std::move(open[static_cast<size_t>(best)]);
        extend(c, f, r, t, !c.forward);
        next.push_back(std::move(c));
      } else {
        Chain c;
        extend(c, f, r, t, true);
        next.push_back(std::move(c));
      }
    }
    for (size_t k = 0; k < open.size(); ++k)
      if (!taken[k]) out.push_back(std::move(open[k].pts));
    // Keep the chains in the order of their last runs (the next line's search needs it).
    open = std::move(next);
  }
  for (Chain& c : open) out.push_back(std::move(c.pts));
  return out;
}

}  // namespace stipplot::hatch
