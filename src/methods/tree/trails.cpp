#include "methods/tree/trails.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stipplot::tree {

namespace {

// Compressed adjacency: for vertex v, items [start[v], start[v+1]) of `item`.
struct Adjacency {
  std::vector<uint32_t> start, item;
  Adjacency(size_t vertices, const std::vector<TrailEdge>& edges) : start(vertices + 1, 0), item(2 * edges.size()) {
    for (const TrailEdge& e : edges) ++start[e.a + 1], ++start[e.b + 1];
    for (size_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t k = 0; k < edges.size(); ++k) item[fill[edges[k].a]++] = k, item[fill[edges[k].b]++] = k;
  }
};

uint32_t other(const TrailEdge& e, uint32_t v) { return e.a == v ? e.b : e.a; }

// Hierholzer's walk from `from` over unused edges; appends the closed walk's vertices and,
// between them, the edges taken (edge_seq[i] joins vertex_seq[i] and vertex_seq[i + 1]).
void walk(uint32_t from, const std::vector<TrailEdge>& edges, const Adjacency& adj, std::vector<uint32_t>& next,
          std::vector<uint8_t>& used, std::vector<uint32_t>& vertex_seq, std::vector<uint32_t>& edge_seq) {
  constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  std::vector<std::pair<uint32_t, uint32_t>> stack{{from, kNone}};
  std::vector<std::pair<uint32_t, uint32_t>> out;
  while (!stack.empty()) {
    const uint32_t v = stack.back().first;
    uint32_t& i = next[v];
    while (i < adj.start[v + 1] && used[adj.item[i]]) ++i;
    if (i < adj.start[v + 1]) {
      const uint32_t k = adj.item[i];
      used[k] = 1;
      stack.push_back({other(edges[k], v), k});
    } else {
      out.push_back(stack.back());
      stack.pop_back();
    }
  }
  // `out` is the circuit reversed: vertex j reached by edge out[j].second from vertex j+1.
  for (size_t j = out.size(); j-- > 0;) {
    vertex_seq.push_back(out[j].first);
    if (j > 0) edge_seq.push_back(out[j - 1].second);
  }
}

}  // namespace

TrailPlan forest_trails(const std::vector<Vec2>& pos, const std::vector<TrailEdge>& edges, double lift_length) {
  TrailPlan plan;
  const size_t nv = pos.size(), ne = edges.size();
  if (ne == 0) return plan;
  const Adjacency adj(nv, edges);
  auto length = [&](uint32_t k) { return std::hypot(pos[edges[k].b].x - pos[edges[k].a].x, pos[edges[k].b].y - pos[edges[k].a].y); };

  // Root every tree; preorder with each vertex's parent edge.
  constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> parent_edge(nv, kNone), order;
  std::vector<uint8_t> seen(nv, 0);
  order.reserve(nv);
  for (uint32_t r = 0; r < nv; ++r) {
    if (seen[r] || adj.start[r] == adj.start[r + 1]) continue;
    std::vector<uint32_t> stack{r};
    seen[r] = 1;
    while (!stack.empty()) {
      const uint32_t v = stack.back();
      stack.pop_back();
      order.push_back(v);
      for (uint32_t i = adj.start[v]; i < adj.start[v + 1]; ++i) {
        const uint32_t k = adj.item[i], w = other(edges[k], v);
        if (k == parent_edge[v]) continue;
        if (seen[w]) continue;  // a cycle: not a forest; the edge is still drawn (once), see below
        seen[w] = 1;
        parent_edge[w] = k;
        stack.push_back(w);
      }
    }
  }

  // The DP, children before parents. A vertex of odd final degree costs half a lift (a
  // trail has two ends); a tree with no odd vertex is one closed trail and costs a whole
  // lift at its root, so a state also says whether its subtree has an odd vertex (z).
  // While v's children are combined, g[v][q][z] is the least cost of them and their
  // subtrees with their edges' multiplicities of parity q; via[k] records, for each state
  // (q, z) reached with child edge k, bit 0: k drawn twice, bit 1: the child's z, bit 2:
  // the z before k. cost[v][m - 1][zv]: least cost of v's subtree with its parent edge
  // drawn m times and zv = any odd vertex in it; at[v] the children's (q, z) behind it.
  const double half = lift_length / 2, inf = std::numeric_limits<double>::infinity();
  struct Table {
    double c[2][2];
  };
  auto state = [](int q, int z) { return q * 2 + z; };
  std::vector<Table> g(nv), cost(nv, Table{{{inf, inf}, {inf, inf}}});
  std::vector<uint16_t> via(ne, 0), at(nv, 0);
  for (size_t j = order.size(); j-- > 0;) {
    const uint32_t v = order[j];
    Table cur{{{0, inf}, {inf, inf}}};  // no child yet: parity 0, no odd vertex
    for (uint32_t i = adj.start[v]; i < adj.start[v + 1]; ++i) {
      const uint32_t k = adj.item[i], c = other(edges[k], v);
      if (k == parent_edge[v] || parent_edge[c] != k) continue;
      Table next{{{inf, inf}, {inf, inf}}};
      uint16_t how = 0;
      for (int q = 0; q < 2; ++q)
        for (int z = 0; z < 2; ++z) {
          if (cur.c[q][z] == inf) continue;
          // Single before twice, replaced only by a strictly better retrace: no ink drawn
          // twice for nothing.
          for (int twice = 0; twice < 2; ++twice)
            for (int zc = 0; zc < 2; ++zc) {
              const double total = cur.c[q][z] + cost[c].c[twice][zc] + (twice ? length(k) : 0);
              const int nq = twice ? q : q ^ 1, nz = z | zc;
              if (total < next.c[nq][nz]) {
                next.c[nq][nz] = total;
                const int sh = 3 * state(nq, nz);
                how = static_cast<uint16_t>((how & ~(7 << sh)) | ((twice | (zc << 1) | (z << 2)) << sh));
              }
            }
        }
      via[k] = how;
      cur = next;
    }
    g[v] = cur;
    for (int m = 1; m <= 2; ++m)
      for (int q = 0; q < 2; ++q)
        for (int z = 0; z < 2; ++z) {
          const int odd = (m + q) & 1, zv = z | odd;
          const double c = cur.c[q][z] + (odd ? half : 0);
          if (c < cost[v].c[m - 1][zv]) {
            cost[v].c[m - 1][zv] = c;
            const int slot = 2 * ((m - 1) * 2 + zv);
            at[v] = static_cast<uint16_t>((at[v] & ~(3 << slot)) | (state(q, z) << slot));
          }
        }
  }
  // Multiplicities, parents before children: each vertex's children state (q, z) from its
  // parent edge's multiplicity and the z its parent chose for it (a root: the best (q, z),
  // a closed tree paying its lift).
  std::vector<uint8_t> mult(ne, 1), z_for(nv, 0);
  for (uint32_t v : order) {
    const uint32_t pe = parent_edge[v];
    int st = 0;
    if (pe == kNone) {
      double best = inf;
      for (int q = 0; q < 2; ++q)
        for (int z = 0; z < 2; ++z) {
          const double c = g[v].c[q][z] + (q ? half : 0) + ((z | q) ? 0 : lift_length);
          if (c < best) best = c, st = state(q, z);
        }
    } else {
      st = (at[v] >> (2 * ((mult[pe] - 1) * 2 + z_for[v]))) & 3;
    }
    int q = st >> 1, z = st & 1;
    for (uint32_t i = adj.start[v + 1]; i-- > adj.start[v];) {
      const uint32_t k = adj.item[i], c = other(edges[k], v);
      if (k == parent_edge[v] || parent_edge[c] != k) continue;
      const int bits = (via[k] >> (3 * state(q, z))) & 7;
      const int twice = bits & 1;
      mult[k] = static_cast<uint8_t>(twice ? 2 : 1);
      z_for[c] = static_cast<uint8_t>((bits >> 1) & 1);
      if (!twice) q ^= 1;
      z = (bits >> 2) & 1;
    }
  }

  // The multigraph (each edge once or twice) plus a virtual vertex joined to every odd
  // vertex: one closed walk through it is the trails, split where it passes the virtual vertex.
  std::vector<TrailEdge> copies;
  std::vector<uint8_t> virtual_edge;
  std::vector<uint32_t> degree(nv + 1, 0);
  for (uint32_t k = 0; k < ne; ++k)
    for (int c = 0; c < mult[k]; ++c) {
      copies.push_back(edges[k]);
      virtual_edge.push_back(0);
      degree[edges[k].a]++, degree[edges[k].b]++;
      if (c == 1) ++plan.retraced_edges, plan.retraced_length += length(k);
    }
  const uint32_t hub = static_cast<uint32_t>(nv);
  for (uint32_t v = 0; v < nv; ++v)
    if (degree[v] & 1) copies.push_back({hub, v}), virtual_edge.push_back(1);
  const Adjacency all(nv + 1, copies);
  std::vector<uint32_t> next(all.start.begin(), all.start.end() - 1);
  std::vector<uint8_t> used(copies.size(), 0);
  auto emit = [&](const std::vector<uint32_t>& vs, const std::vector<uint32_t>& es) {
    std::vector<uint32_t> trail;
    for (size_t i = 0; i < vs.size(); ++i) {
      if (vs[i] != hub) trail.push_back(vs[i]);
      const bool cut = i + 1 == vs.size() || virtual_edge[es[i]];
      if (cut) {
        if (trail.size() >= 2) plan.trails.push_back(std::move(trail));
        trail.clear();
      }
    }
  };
  std::vector<uint32_t> vs, es;
  if (all.start[hub] != all.start[hub + 1]) {
    walk(hub, copies, all, next, used, vs, es);
    emit(vs, es);
  }
  for (uint32_t k = 0; k < copies.size(); ++k) {  // trees whose every vertex is even: closed trails
    if (used[k]) continue;
    vs.clear(), es.clear();
    walk(copies[k].a, copies, all, next, used, vs, es);
    emit(vs, es);
  }
  return plan;
}

namespace {

// A closed loop (last point = first) with every corner cut `rounds` times at a quarter.
void cut_corners(Polyline& loop, int rounds) {
  for (int r = 0; r < rounds && loop.pts.size() > 2; ++r) {
    std::vector<Vec2> q;
    q.reserve(2 * loop.pts.size());
    for (size_t i = 0; i + 1 < loop.pts.size(); ++i) {
      const Vec2 a = loop.pts[i], b = loop.pts[i + 1];
      q.push_back({0.75 * a.x + 0.25 * b.x, 0.75 * a.y + 0.25 * b.y});
      q.push_back({0.25 * a.x + 0.75 * b.x, 0.25 * a.y + 0.75 * b.y});
    }
    q.push_back(q.front());
    loop.pts = std::move(q);
  }
}

}  // namespace

std::vector<Polyline> forest_outlines(const std::vector<Vec2>& pos, const std::vector<TrailEdge>& edges, double offset,
                                      int rounds) {
  std::vector<Polyline> loops;
  const size_t nv = pos.size(), ne = edges.size();
  if (ne == 0) return loops;
  // Half-edge h = 2k (a -> b) or 2k + 1 (b -> a) of edge k, its unit direction once.
  auto from = [&](uint32_t h) { return h & 1 ? edges[h >> 1].b : edges[h >> 1].a; };
  auto to = [&](uint32_t h) { return h & 1 ? edges[h >> 1].a : edges[h >> 1].b; };
  std::vector<Vec2> unit(2 * ne);
  std::vector<double> angle(2 * ne);
  for (uint32_t h = 0; h < 2 * ne; ++h) {
    const Vec2 p = pos[from(h)], q = pos[to(h)];
    const double len = std::hypot(q.x - p.x, q.y - p.y);
    unit[h] = len > 0 ? Vec2{(q.x - p.x) / len, (q.y - p.y) / len} : Vec2{1, 0};
    angle[h] = std::atan2(unit[h].y, unit[h].x);
  }
  auto dir = [&](uint32_t h) { return unit[h]; };
  // Each vertex's outgoing half-edges (the edges of its adjacency, as leaving it) sorted
  // by angle; rank[h]: h's place among them.
  const Adjacency adj(nv, edges);
  const std::vector<uint32_t>& start = adj.start;
  std::vector<uint32_t> out(2 * ne), rank(2 * ne);
  for (uint32_t v = 0; v < nv; ++v) {
    for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
      const uint32_t k = adj.item[i];
      out[i] = 2 * k + (edges[k].a == v ? 0 : 1);
    }
    std::sort(out.begin() + start[v], out.begin() + start[v + 1],
              [&](uint32_t x, uint32_t y) { return angle[x] < angle[y] || (angle[x] == angle[y] && x < y); });
    for (uint32_t i = start[v]; i < start[v + 1]; ++i) rank[out[i]] = i;
  }
  // After arriving at v by h, leave by the half-edge next below the way back (h ^ 1) in
  // angle: with the offset on the left of the walk, that is the edge whose side meets it.
  auto next = [&](uint32_t h) {
    const uint32_t back = h ^ 1, v = from(back);
    const uint32_t i = rank[back];
    return out[i == start[v] ? start[v + 1] - 1 : i - 1];
  };
  auto left = [](Vec2 t) { return Vec2{-t.y, t.x}; };
  std::vector<uint8_t> done(2 * ne, 0);
  constexpr double kArcStep = M_PI / 4;  // outer corners: arc points at most 45 degrees apart
  for (uint32_t h0 = 0; h0 < 2 * ne; ++h0) {
    if (done[h0]) continue;
    Polyline pl;
    uint32_t h = h0;
    do {
      done[h] = 1;
      const uint32_t g = next(h);
      const Vec2 v = pos[to(h)], t1 = dir(h), t2 = dir(g), n1 = left(t1), n2 = left(t2);
      const double cross = t1.x * t2.y - t1.y * t2.x, dot = t1.x * t2.x + t1.y * t2.y;
      if (g != (h ^ 1) && cross >= 0) {
        // Straight on, or an inner corner (the walk turns toward its offset side): the
        // offset lines meet; where they meet far out (a sharp turn), a bevel.
        const double s = 1 + dot > 1e-6 ? offset / (1 + dot) : 0;
        const Vec2 m{v.x + s * (n1.x + n2.x), v.y + s * (n1.y + n2.y)};
        const double reach = s > 0 ? s * std::hypot(n1.x + n2.x, n1.y + n2.y) : HUGE_VAL;
        const double l1 = std::hypot(v.x - pos[from(h)].x, v.y - pos[from(h)].y);
        const double l2 = std::hypot(pos[to(g)].x - v.x, pos[to(g)].y - v.y);
        if (reach <= 0.5 * std::min(l1, l2)) {
          pl.pts.push_back(m);
        } else {
          pl.pts.push_back({v.x + offset * n1.x, v.y + offset * n1.y});
          pl.pts.push_back({v.x + offset * n2.x, v.y + offset * n2.y});
        }
      } else {
        // An outer corner or a tip: round it, from n1 turning clockwise to n2.
        double a1 = std::atan2(n1.y, n1.x), a2 = std::atan2(n2.y, n2.x);
        while (a2 > a1) a2 -= 2 * M_PI;
        if (g == (h ^ 1)) a2 = a1 - M_PI;  // a tip: the half circle round it
        const int steps = std::max(1, static_cast<int>(std::ceil((a1 - a2) / kArcStep - 1e-9)));
        for (int i = 0; i <= steps; ++i) {
          const double a = a1 + (a2 - a1) * i / steps;
          pl.pts.push_back({v.x + offset * std::cos(a), v.y + offset * std::sin(a)});
        }
      }
      h = g;
    } while (h != h0);
    if (pl.pts.empty()) continue;
    pl.pts.push_back(pl.pts.front());  // closed
    cut_corners(pl, rounds);
    loops.push_back(std::move(pl));
  }
  return loops;
}

}  // namespace stipplot::tree
