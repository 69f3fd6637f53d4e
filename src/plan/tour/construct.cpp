#include "construct.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "spatial/kdtree.hpp"
#include "spatial/knn.hpp"
#include "util/threads.hpp"

namespace stipplot::plan::tour {

std::vector<uint32_t> nearest_neighbour_path(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner,
                                             Vec2 start) {
  spatial::PlaneTree tree = spatial::plane_tree(pts);
  std::vector<uint32_t> order;
  order.reserve(pts.size());
  Vec2 cur = start;
  while (tree.alive() > 0) {
    const uint32_t j = tree.take_nearest(spatial::plane_point(cur));
    order.push_back(j);
    cur = pts[j];
    if (partner[j] >= 0) {
      const uint32_t k = static_cast<uint32_t>(partner[j]);
      tree.erase(k);
      order.push_back(k);
      cur = pts[k];
    }
  }
  return order;
}

namespace {

// Sorted lists merged into one sorted list, pair by pair. O(total log lists).
std::vector<uint64_t> merge_sorted(std::vector<std::vector<uint64_t>> lists) {
  if (lists.empty()) return {};
  while (lists.size() > 1) {
    std::vector<std::vector<uint64_t>> next;
    for (size_t i = 0; i + 1 < lists.size(); i += 2) {
      std::vector<uint64_t> both(lists[i].size() + lists[i + 1].size());
      std::merge(lists[i].begin(), lists[i].end(), lists[i + 1].begin(), lists[i + 1].end(), both.begin());
      std::vector<uint64_t>().swap(lists[i]);
      std::vector<uint64_t>().swap(lists[i + 1]);
      next.push_back(std::move(both));
    }
    if (lists.size() % 2) next.push_back(std::move(lists.back()));
    lists = std::move(next);
  }
  return std::move(lists[0]);
}

// Path fragments as a graph of degree at most 2, with union-find to refuse cycles.
class Fragments {
 public:
  explicit Fragments(uint32_t n) : adj_(2 * static_cast<size_t>(n), kNoNode), root_(n), count_(n) {
    for (uint32_t i = 0; i < n; ++i) root_[i] = i;
  }
  bool full(uint32_t v) const { return adj_[2 * static_cast<size_t>(v) + 1] != kNoNode; }
  bool link(uint32_t a, uint32_t b) {
    if (full(a) || full(b)) return false;
    const uint32_t ra = find(a), rb = find(b);
    if (ra == rb) return false;
    root_[std::max(ra, rb)] = std::min(ra, rb);  // by index: deterministic, and shallow enough with halving
    --count_;
    attach(a, b);
    attach(b, a);
    return true;
  }
  // The neighbour of v other than `from` (kNoNode at a fragment's end).
  uint32_t step(uint32_t v, uint32_t from) const {
    const uint32_t x = adj_[2 * static_cast<size_t>(v)];
    return x == from ? adj_[2 * static_cast<size_t>(v) + 1] : x;
  }
  bool is_end(uint32_t v) const { return !full(v); }
  uint32_t fragment_of(uint32_t v) { return find(v); }
  uint32_t count() const { return count_; }  // fragments, lone nodes included

 private:
  uint32_t find(uint32_t v) {
    while (root_[v] != v) v = root_[v] = root_[root_[v]];
    return v;
  }
  void attach(uint32_t v, uint32_t w) {
    const size_t s = 2 * static_cast<size_t>(v);
    adj_[adj_[s] == kNoNode ? s : s + 1] = w;
  }
  std::vector<uint32_t> adj_;
  std::vector<uint32_t> root_;
  uint32_t count_;
};

// Candidate edges (each once) sorted by length, ties by (node, rank): 64-bit keys of
// the float length's bits (ordered like the lengths, all being >= 0) and the slot.
// On threads from 8,000 nodes: each thread keys and sorts a block of rows, and the blocks
// are merged; the keys are distinct, so the list is the same on any thread count.
std::vector<uint64_t> sorted_candidate_edges(const std::vector<Vec2>& pts, const Candidates& cand) {
  const uint32_t n = static_cast<uint32_t>(pts.size()), k = cand.k;
  // The 5 nearest suffice: the rounds among fragment ends join what they leave.
  const uint32_t kg = std::min(k, 5u);
  auto key_rows = [&](uint32_t from, uint32_t to, std::vector<uint64_t>& keys) {
    keys.reserve(static_cast<size_t>(to - from) * kg * 2 / 3);
    for (uint32_t i = from; i < to; ++i) {
      const uint32_t* row = cand.row(i);
      for (uint32_t s = 0; s < kg && row[s] != kNoNode; ++s) {
        const uint32_t j = row[s];
        // Keep (i, j) from the lower index, or from i when j's list lacks i.
        if (j < i && std::find(cand.row(j), cand.row(j) + kg, i) != cand.row(j) + kg) continue;
        const double dx = pts[i].x - pts[j].x, dy = pts[i].y - pts[j].y;
        const float len = static_cast<float>(std::sqrt(dx * dx + dy * dy));
        keys.push_back(static_cast<uint64_t>(std::bit_cast<uint32_t>(len)) << 32 | (static_cast<uint64_t>(i) * k + s));
      }
    }
    std::sort(keys.begin(), keys.end());
  };
  const int parts = n >= 8'000 && !in_parallel_part() ? std::max(1, thread_count()) : 1;
  std::vector<std::vector<uint64_t>> part(static_cast<size_t>(parts));
#pragma omp parallel for num_threads(parts) schedule(static, 1) if (parts > 1)
  for (int t = 0; t < parts; ++t)
    key_rows(static_cast<uint32_t>(uint64_t{n} * t / parts), static_cast<uint32_t>(uint64_t{n} * (t + 1) / parts), part[t]);
  return merge_sorted(std::move(part));
}

// Greedy matching again among the fragments' free ends only, round after round (each
// round's candidates are the ends' nearest ends of other fragments), so fragments are
// joined by short edges rather than by one nearest-end walk that leaves long jumps
// for 2-opt to undo with long reversals. O(f log f) a round for f fragments.
void join_fragment_ends(const std::vector<Vec2>& pts, Fragments& frag) {
  constexpr uint32_t k = 8;
  const uint32_t n = static_cast<uint32_t>(pts.size());
  while (frag.count() > 1) {
    std::vector<uint32_t> ends;
    std::vector<Vec2> end_pts;
    for (uint32_t v = 0; v < n; ++v)
      if (frag.is_end(v)) ends.push_back(v), end_pts.push_back(pts[v]);
    const uint32_t m = static_cast<uint32_t>(ends.size());
    const spatial::PlaneKnn knn(end_pts, m);
    std::vector<uint32_t> near(static_cast<size_t>(m) * k, kNoNode), fragment(m);
    for (uint32_t i = 0; i < m; ++i) fragment[i] = frag.fragment_of(ends[i]);  // (finding compresses paths)
    // Each end's nearest on every thread (the searches only read); the keys are distinct,
    // so once sorted they are the same in whatever order the threads found them.
    std::vector<std::vector<uint64_t>> found(static_cast<size_t>(std::max(1, thread_count())));
#pragma omp parallel num_threads(thread_count()) if (m >= 4'000 && !in_parallel_part())
    {
      std::vector<uint32_t> idx(k + 1);
      std::vector<double> d2(k + 1);
      std::vector<uint64_t>& mine = found[static_cast<size_t>(thread_index())];
#pragma omp for schedule(dynamic, 1024)
      for (long li = 0; li < static_cast<long>(m); ++li) {
        const uint32_t i = static_cast<uint32_t>(li);
        const size_t got = knn.k_nearest(end_pts[i], k + 1, idx.data(), d2.data());
        uint32_t s = 0;
        for (size_t j = 0; j < got && s < k; ++j) {
          if (idx[j] == i || fragment[i] == fragment[idx[j]]) continue;
          if (idx[j] < i) continue;  // (j, i) is j's
          near[static_cast<size_t>(i) * k + s] = idx[j];
          const float len = static_cast<float>(std::sqrt(d2[j]));
          mine.push_back(static_cast<uint64_t>(std::bit_cast<uint32_t>(len)) << 32 | (static_cast<uint64_t>(i) * k + s));
          ++s;
        }
      }
      std::sort(mine.begin(), mine.end());
    }
    const std::vector<uint64_t> keys = merge_sorted(std::move(found));
    const uint32_t before = frag.count();
    for (const uint64_t key : keys) {
      const uint32_t slot = static_cast<uint32_t>(key);
      frag.link(ends[slot / k], ends[near[slot]]);
    }
    // A round normally joins most fragments; where it joins few (ends whose nearest
    // ends are their own fragment's, as among many coincident points) the rest is left
    // to the nearest-end walk rather than to many more rounds.
    if (4 * static_cast<uint64_t>(before - frag.count()) < before) break;
  }
}

}  // namespace

std::vector<uint32_t> greedy_edge_path(const std::vector<Vec2>& pts, const std::vector<int32_t>& partner, Vec2 start,
                                       const Candidates& cand) {
  const uint32_t n = static_cast<uint32_t>(pts.size()), k = cand.k;
  // Slots i * k + s must fit the key's low 32 bits.
  if (static_cast<uint64_t>(n) * k >= (uint64_t{1} << 32)) return nearest_neighbour_path(pts, partner, start);
  Fragments frag(n);
  for (uint32_t i = 0; i < n; ++i)
    if (partner[i] > static_cast<int32_t>(i)) frag.link(i, static_cast<uint32_t>(partner[i]));
  for (const uint64_t key : sorted_candidate_edges(pts, cand)) {
    const uint32_t slot = static_cast<uint32_t>(key);
    frag.link(slot / k, cand.row(slot / k)[slot % k]);
  }
  join_fragment_ends(pts, frag);
  // Fragment ends (a lone node is both ends of its fragment), each paired with the other end.
  std::vector<uint32_t> ends, other(n, kNoNode), end_index(n, kNoNode);
  for (uint32_t v = 0; v < n; ++v) {
    if (!frag.is_end(v) || other[v] != kNoNode) continue;
    uint32_t prev = kNoNode, cur = v;
    for (uint32_t nx = frag.step(cur, prev); nx != kNoNode; nx = frag.step(cur, prev)) prev = cur, cur = nx;
    other[v] = cur;
    other[cur] = v;
    end_index[v] = static_cast<uint32_t>(ends.size());
    ends.push_back(v);
    if (cur != v) {
      end_index[cur] = static_cast<uint32_t>(ends.size());
      ends.push_back(cur);
    }
  }
  std::vector<Vec2> end_pts(ends.size());
  for (size_t i = 0; i < ends.size(); ++i) end_pts[i] = pts[ends[i]];
  spatial::PlaneTree tree = spatial::plane_tree(end_pts);
  std::vector<uint32_t> order;
  order.reserve(n);
  Vec2 cur = start;
  while (tree.alive() > 0) {
    const uint32_t e = ends[tree.take_nearest(spatial::plane_point(cur))];
    const uint32_t o = other[e];
    if (o != e) tree.erase(end_index[o]);
    uint32_t prev = kNoNode;
    for (uint32_t v = e; v != kNoNode;) {
      order.push_back(v);
      const uint32_t nx = frag.step(v, prev);
      prev = v;
      v = nx;
    }
    cur = pts[o];
  }
  return order;
}

}  // namespace stipplot::plan::tour
