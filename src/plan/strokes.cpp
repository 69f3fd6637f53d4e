#include "plan/strokes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_set>

#include "geometry/shapes.hpp"
#include "spatial/kdtree.hpp"
#include "util/error.hpp"

namespace stipplot::plan {

namespace {

// Merges points closer than `tol` into shared vertices by hashing on a grid of
// cell size tol; each lookup scans the 3x3 cells around the point. The cells are an
// open-addressing table of (cell, its latest vertex), each vertex linking the one before
// it in its cell: no allocation a cell (sketch's 25,000 ground lines: 38 -> 9-12 ms). Which
// vertex a point takes does not depend on the order a cell lists them (nearest, then
// the lowest number).
class VertexSnap {
 public:
  explicit VertexSnap(double tol) : tol_(tol), cell_(std::max(tol, 1e-9)) {}
  uint32_t id(Vec2 p) {
    const int64_t cx = static_cast<int64_t>(std::floor(p.x / cell_));
    const int64_t cy = static_cast<int64_t>(std::floor(p.y / cell_));
    uint32_t best = UINT32_MAX;
    double best_d2 = tol_ * tol_;
    for (int64_t dy = -1; dy <= 1; ++dy)
      for (int64_t dx = -1; dx <= 1; ++dx)
        for (uint32_t v = slot(cx + dx, cy + dy).head; v != UINT32_MAX; v = before_[v]) {
          double ex = pts[v].x - p.x, ey = pts[v].y - p.y, d2 = ex * ex + ey * ey;
          if (d2 <= best_d2 && (best == UINT32_MAX || d2 < best_d2 || v < best)) best = v, best_d2 = d2;
        }
    if (best != UINT32_MAX) return best;
    const uint32_t v = static_cast<uint32_t>(pts.size());
    pts.push_back(p);
    Slot& s = slot(cx, cy);
    const bool fresh = s.head == UINT32_MAX;
    before_.push_back(s.head);
    s.x = cx, s.y = cy, s.head = v;
    if (fresh && 2 * ++used_ > table_.size()) grow();
    return v;
  }
  std::vector<Vec2> pts;

 private:
  struct Slot {
    int64_t x = 0, y = 0;
    uint32_t head = UINT32_MAX;  // the cell's latest vertex; UINT32_MAX: the slot is free
  };
  static size_t hash(int64_t x, int64_t y) {
    return static_cast<size_t>((static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ULL) ^
                               (static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4FULL)) >> 7;
  }
  // The cell's slot, or the free one where it would go (linear probing).
  Slot& slot(int64_t x, int64_t y) {
    const size_t mask = table_.size() - 1;
    for (size_t i = hash(x, y) & mask;; i = (i + 1) & mask) {
      Slot& s = table_[i];
      if (s.head == UINT32_MAX || (s.x == x && s.y == y)) return s;
    }
  }
  void grow() {
    std::vector<Slot> old(table_.size() * 2);
    old.swap(table_);
    for (const Slot& s : old)
      if (s.head != UINT32_MAX) slot(s.x, s.y) = s;
  }
  double tol_, cell_;
  std::vector<Slot> table_ = std::vector<Slot>(64);
  size_t used_ = 0;
  std::vector<uint32_t> before_;  // per vertex: the one added to its cell before it
};

void append_points(Stroke& s, const std::vector<Vec2>& pts, bool reversed) {
  const size_t n = pts.size();
  // Room for all of them at once, growing geometrically still: a tree's outline of 433,000
  // points is one allocation, not twenty reallocations each faulting in fresh pages.
  if (s.pts.capacity() < s.pts.size() + n) s.pts.reserve(std::max(s.pts.size() + n, 2 * s.pts.capacity()));
  for (size_t k = 0; k < n; ++k) {
    const Vec2& p = reversed ? pts[n - 1 - k] : pts[k];
    if (!s.pts.empty() && s.pts.back() == p) continue;
    s.pts.push_back(p);
  }
}

}  // namespace

namespace {

struct GEdge {
  uint32_t u, v;
  int32_t line;  // -1: virtual (pen-up) edge pairing two odd vertices
};

// Pairs odd-degree vertices nearest-first with virtual edges. Any pairing inside a
// component makes it Eulerian; pairs across components would merge them, so the
// pairing runs per component. O(V log V).
void pair_odd_vertices(const std::vector<Vec2>& vertex, std::vector<GEdge>& edges) {
  const uint32_t nv = static_cast<uint32_t>(vertex.size());
  std::vector<uint32_t> degree(nv, 0);
  for (const auto& e : edges) ++degree[e.u], ++degree[e.v];
  std::vector<uint32_t> comp(nv);
  {
    std::vector<uint32_t> parent(nv);
    for (uint32_t i = 0; i < nv; ++i) parent[i] = i;
    auto find = [&](uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (const auto& e : edges) {
      uint32_t a = find(e.u), b = find(e.v);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
    for (uint32_t i = 0; i < nv; ++i) comp[i] = find(i);
  }
  // The odd vertices grouped by component, the components in first-seen order and each
  // one's vertices in increasing order (a counting sort: no list a component).
  std::vector<uint32_t> rank(nv, UINT32_MAX), count;
  for (uint32_t v = 0; v < nv; ++v) {
    if (degree[v] % 2 == 0) continue;
    uint32_t& r = rank[comp[v]];
    if (r == UINT32_MAX) r = static_cast<uint32_t>(count.size()), count.push_back(0);
    ++count[r];
  }
  std::vector<uint32_t> begin(count.size() + 1, 0);
  for (size_t r = 0; r < count.size(); ++r) begin[r + 1] = begin[r] + count[r];
  std::vector<uint32_t> odd_all(begin.back()), fill(begin.begin(), begin.end() - 1);
  for (uint32_t v = 0; v < nv; ++v)
    if (degree[v] % 2 != 0) odd_all[fill[rank[comp[v]]]++] = v;
  std::unordered_set<uint32_t> paired;
  for (size_t r = 0; r < count.size(); ++r) {
    const uint32_t* odd = odd_all.data() + begin[r];
    const uint32_t m = count[r];
    if (m == 2) {  // a chain's two ends: what the nearest-first pairing below gives
      edges.push_back({odd[0], odd[1], -1});
      continue;
    }
    std::vector<Vec2> p(m);
    for (size_t k = 0; k < m; ++k) p[k] = vertex[odd[k]];
    spatial::PlaneTree tree = spatial::plane_tree(p);
    for (uint32_t k = 0; k < m; ++k) {
      if (tree.alive() == 0) break;
      if (paired.count(k)) continue;
      tree.erase(k);
      const uint32_t b = tree.take_nearest(spatial::plane_point(p[k]));
      paired.insert(b);
      edges.push_back({odd[k], odd[b], -1});
    }
    paired.clear();
  }
}

// Walks an Euler circuit of every component (Hierholzer: depth-first until stuck,
// emitting edges while backtracking), cuts it at the virtual edges and appends the
// pieces as strokes. O(E + V).
void euler_strokes(const std::vector<GEdge>& edges, uint32_t nv, const std::vector<Polyline>& lines,
                   std::vector<Stroke>& out) {
  // Adjacency in CSR form.
  std::vector<uint32_t> start(nv + 1, 0);
  for (const auto& e : edges) ++start[e.u + 1], ++start[e.v + 1];
  for (uint32_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<uint32_t> adj(start[nv]), fill(start.begin(), start.end() - 1);
  for (uint32_t i = 0; i < edges.size(); ++i) {
    adj[fill[edges[i].u]++] = i;
    adj[fill[edges[i].v]++] = i;
  }
  std::vector<uint32_t> next_edge(start.begin(), start.end() - 1);
  std::vector<uint8_t> used(edges.size(), 0), visited(nv, 0);

  struct Step {
    uint32_t edge;
    bool forward;  // traversed u -> v
  };
  std::vector<std::pair<uint32_t, int64_t>> stack;  // vertex, arriving step (edge*2+dir) or -1
  std::vector<Step> circuit;
  for (uint32_t root = 0; root < nv; ++root) {
    if (visited[root] || start[root] == start[root + 1]) continue;
    circuit.clear();
    stack.assign(1, {root, -1});
    while (!stack.empty()) {
      const uint32_t v = stack.back().first;
      visited[v] = 1;
      uint32_t& k = next_edge[v];
      while (k < start[v + 1] && used[adj[k]]) ++k;
      if (k < start[v + 1]) {
        const uint32_t e = adj[k];
        used[e] = 1;
        const bool fwd = edges[e].u == v;
        const uint32_t w = fwd ? edges[e].v : edges[e].u;
        stack.push_back({w, static_cast<int64_t>(e) * 2 + (fwd ? 1 : 0)});
      } else {
        if (stack.back().second >= 0)
          circuit.push_back({static_cast<uint32_t>(stack.back().second / 2), (stack.back().second & 1) != 0});
        stack.pop_back();
      }
    }
    std::reverse(circuit.begin(), circuit.end());
    // Cut at virtual edges: start right after one, if any.
    size_t first = 0;
    for (size_t k = 0; k < circuit.size(); ++k)
      if (edges[circuit[k].edge].line < 0) {
        first = k + 1;
        break;
      }
    Stroke cur;
    for (size_t s = 0; s < circuit.size(); ++s) {
      const Step& st = circuit[(first + s) % circuit.size()];
      const GEdge& e = edges[st.edge];
      if (e.line < 0) {
        if (!cur.pts.empty()) out.push_back(std::move(cur));
        cur = Stroke{};
        continue;
      }
      append_points(cur, lines[static_cast<size_t>(e.line)].pts, !st.forward);
    }
    if (!cur.pts.empty()) out.push_back(std::move(cur));
  }
}

}  // namespace

std::vector<Stroke> join_polylines(const std::vector<Polyline>& lines, double tolerance) {
  std::vector<Stroke> out;
  VertexSnap snap(tolerance);
  std::vector<GEdge> edges;
  for (size_t i = 0; i < lines.size(); ++i) {
    const auto& pts = lines[i].pts;
    if (pts.empty()) continue;
    if (pts.size() == 1) {
      out.push_back({{pts[0]}});
      continue;
    }
    uint32_t u = snap.id(pts.front());
    uint32_t v = snap.id(pts.back());
    edges.push_back({u, v, static_cast<int32_t>(i)});
  }
  if (edges.empty()) return out;
  pair_odd_vertices(snap.pts, edges);
  euler_strokes(edges, static_cast<uint32_t>(snap.pts.size()), lines, out);
  return out;
}

FillMode parse_fill_mode(const std::string& name) {
  if (name == "spiral") return FillMode::Spiral;
  if (name == "hatch") return FillMode::Hatch;
  if (name == "none") return FillMode::None;
  throw UserError("--fill must be spiral, hatch or none (got '" + name + "')");
}

const char* to_string(FillMode m) {
  switch (m) {
    case FillMode::Spiral: return "spiral";
    case FillMode::Hatch: return "hatch";
    case FillMode::None: return "none";
  }
  return "?";
}

Stroke circle_outline(Vec2 c, double r, double chord_tolerance, double start_angle) {
  return Stroke{circle_points(c, r, chord_tolerance, start_angle)};
}

Stroke circle_stroke(const Circle& circle, const FillOptions& opt) {
  const double w = opt.pen_width;
  if (2 * circle.r <= w) return Stroke{{circle.c}};
  if (!circle.filled) return circle_outline(circle.c, circle.r, opt.chord_tolerance);
  const double R = circle.r - w / 2;  // centre line of the outermost pass
  if (opt.mode == FillMode::None) return circle_outline(circle.c, R, opt.chord_tolerance);
  const double max_pitch = opt.pitch_fraction * w;
  const double passes = std::ceil(R / max_pitch) * (opt.mode == FillMode::Hatch ? 2 : 1);
  const double per_pass = opt.mode == FillMode::Hatch ? 2 : 2 * std::numbers::pi / chord_angle_step(R, opt.chord_tolerance);
  if (passes * per_pass > 2e7)
    throw UserError("a filled circle of radius " + std::to_string(circle.r) + " mm needs too many fill passes at pen width " +
                    std::to_string(w) + " mm");
  const Vec2 c = circle.c;
  Stroke s;
  if (opt.mode == FillMode::Spiral) {
    const int turns = std::max(1, static_cast<int>(std::ceil(R / max_pitch)));
    const double pitch = R / turns;
    const double theta_end = 2 * std::numbers::pi * turns;
    double theta = 0;
    while (true) {
      const double rho = pitch * theta / (2 * std::numbers::pi);
      s.pts.push_back({c.x + rho * std::cos(theta), c.y + rho * std::sin(theta)});
      if (theta >= theta_end) break;
      theta = std::min(theta_end, theta + chord_angle_step(std::max(rho, pitch), opt.chord_tolerance));
    }
    // The spiral ends at angle 0 (a whole number of turns) on radius R: close with
    // the outline from there.
    Stroke ring = circle_outline(c, R, opt.chord_tolerance, 0);
    s.pts.insert(s.pts.end(), ring.pts.begin() + 1, ring.pts.end());
    return s;
  }
  // Hatch: horizontal chords of the radius-R disc, joined in a zigzag along the rim.
  const int gaps = std::max(1, static_cast<int>(std::ceil(2 * R / max_pitch)));
  const double step = 2 * R / gaps;
  for (int k = 0; k <= gaps; ++k) {
    const double y = -R + k * step;
    const double half = std::sqrt(std::max(0.0, R * R - y * y));
    const bool left_to_right = k % 2 == 0;
    Vec2 a{c.x - half, c.y + y}, b{c.x + half, c.y + y};
    if (!left_to_right) std::swap(a, b);
    if (s.pts.empty() || !(s.pts.back() == a)) s.pts.push_back(a);
    if (!(b == a)) s.pts.push_back(b);
  }
  // The last chord ends on the rim at y = +R (angle pi/2): go round from there.
  Stroke ring = circle_outline(c, R, opt.chord_tolerance, std::numbers::pi / 2);
  s.pts.insert(s.pts.end(), ring.pts.begin() + 1, ring.pts.end());
  return s;
}

}  // namespace stipplot::plan
