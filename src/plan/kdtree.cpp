#include "plan/kdtree.hpp"

#include <algorithm>
#include <limits>

namespace stipplot::plan {

namespace {
constexpr uint32_t kLeafSize = 8;
inline double dist2(Vec2 a, Vec2 b) {
  double dx = a.x - b.x, dy = a.y - b.y;
  return dx * dx + dy * dy;
}
}  // namespace

KdTree::KdTree(const std::vector<Vec2>& pts) : pts_(pts) {
  const uint32_t n = static_cast<uint32_t>(pts.size());
  idx_.resize(n);
  for (uint32_t i = 0; i < n; ++i) idx_[i] = i;
  leaf_of_.assign(n, -1);
  dead_.assign(n, 0);
  nodes_.reserve(n / kLeafSize * 2 + 2);
  if (n > 0) build(0, n, -1);
}

int32_t KdTree::build(uint32_t begin, uint32_t end, int32_t parent) {
  const int32_t id = static_cast<int32_t>(nodes_.size());
  nodes_.push_back({});
  Node nd;
  nd.begin = begin;
  nd.end = end;
  nd.parent = parent;
  nd.count = end - begin;
  nd.lox = nd.loy = std::numeric_limits<double>::infinity();
  nd.hix = nd.hiy = -std::numeric_limits<double>::infinity();
  for (uint32_t k = begin; k < end; ++k) {
    const Vec2& p = pts_[idx_[k]];
    nd.lox = std::min(nd.lox, p.x);
    nd.hix = std::max(nd.hix, p.x);
    nd.loy = std::min(nd.loy, p.y);
    nd.hiy = std::max(nd.hiy, p.y);
  }
  if (end - begin <= kLeafSize) {
    for (uint32_t k = begin; k < end; ++k) leaf_of_[idx_[k]] = id;
    nodes_[id] = nd;
    return id;
  }
  const bool split_x = nd.hix - nd.lox >= nd.hiy - nd.loy;
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(idx_.begin() + begin, idx_.begin() + mid, idx_.begin() + end, [&](uint32_t a, uint32_t b) {
    return split_x ? pts_[a].x < pts_[b].x : pts_[a].y < pts_[b].y;
  });
  nodes_[id] = nd;
  const int32_t l = build(begin, mid, id);
  const int32_t r = build(mid, end, id);
  nodes_[id].left = l;
  nodes_[id].right = r;
  return id;
}

double KdTree::box_dist2(const Node& n, Vec2 q) {
  double dx = q.x < n.lox ? n.lox - q.x : (q.x > n.hix ? q.x - n.hix : 0);
  double dy = q.y < n.loy ? n.loy - q.y : (q.y > n.hiy ? q.y - n.hiy : 0);
  return dx * dx + dy * dy;
}

void KdTree::erase(uint32_t i) {
  if (dead_[i]) return;
  dead_[i] = 1;
  for (int32_t n = leaf_of_[i]; n >= 0; n = nodes_[n].parent) --nodes_[n].count;
}

uint32_t KdTree::nearest_alive(Vec2 q) const {
  uint32_t best = UINT32_MAX;
  if (nodes_.empty() || nodes_[0].count == 0) return best;
  double best_d2 = std::numeric_limits<double>::infinity();
  int32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const Node& n = nodes_[stack[--sp]];
    if (n.count == 0 || box_dist2(n, q) >= best_d2) continue;
    if (n.left < 0) {
      for (uint32_t k = n.begin; k < n.end; ++k) {
        uint32_t i = idx_[k];
        if (dead_[i]) continue;
        double d2 = dist2(pts_[i], q);
        if (d2 < best_d2 || (d2 == best_d2 && i < best)) best_d2 = d2, best = i;
      }
      continue;
    }
    // Push the farther child first so the nearer one is searched first.
    double dl = box_dist2(nodes_[n.left], q), dr = box_dist2(nodes_[n.right], q);
    if (dl <= dr) {
      stack[sp++] = n.right;
      stack[sp++] = n.left;
    } else {
      stack[sp++] = n.left;
      stack[sp++] = n.right;
    }
  }
  return best;
}

uint32_t KdTree::label(int32_t id) {
  Node& n = nodes_[id];
  if (n.left < 0) {
    uint32_t c = (*comp_)[idx_[n.begin]];
    for (uint32_t k = n.begin + 1; k < n.end; ++k)
      if ((*comp_)[idx_[k]] != c) c = kMixed;
    return n.comp = c;
  }
  uint32_t a = label(n.left), b = label(n.right);
  return n.comp = (a == b ? a : kMixed);
}

void KdTree::set_components(const std::vector<uint32_t>& comp) {
  comp_ = &comp;
  if (!nodes_.empty()) label(0);
}

uint32_t KdTree::nearest_other(uint32_t self, double& bound2) const {
  uint32_t best = UINT32_MAX;
  if (nodes_.empty()) return best;
  const uint32_t mine = (*comp_)[self];
  const Vec2 q = pts_[self];
  int32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const Node& n = nodes_[stack[--sp]];
    if (n.comp == mine || box_dist2(n, q) >= bound2) continue;
    if (n.left < 0) {
      for (uint32_t k = n.begin; k < n.end; ++k) {
        uint32_t i = idx_[k];
        if ((*comp_)[i] == mine) continue;
        double d2 = dist2(pts_[i], q);
        if (d2 < bound2) bound2 = d2, best = i;
      }
      continue;
    }
    double dl = box_dist2(nodes_[n.left], q), dr = box_dist2(nodes_[n.right], q);
    if (dl <= dr) {
      stack[sp++] = n.right;
      stack[sp++] = n.left;
    } else {
      stack[sp++] = n.left;
      stack[sp++] = n.right;
    }
  }
  return best;
}

}  // namespace stipplot::plan
