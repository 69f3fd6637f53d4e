#include "drivers/device/carousel.hpp"

#include <algorithm>

namespace stipplot {

namespace {

int pen_of(const PlannedLayer& l, size_t index) { return l.pen.number > 0 ? l.pen.number : static_cast<int>(index) + 1; }

// The slot pen p comes home to (0: none, it is beyond the carousel).
int home_slot(const PenSetup& pens, int p) {
  if (!pens.map.empty()) return p <= static_cast<int>(pens.map.size()) ? pens.map[static_cast<size_t>(p - 1)] : 0;
  return p <= pens.count ? p : 0;
}

}  // namespace

std::vector<PenSlot> plan_pen_slots(const Plan& plan, const PenSetup& pens) {
  const int slots = std::max(1, pens.count);
  std::vector<int> holds(static_cast<size_t>(slots) + 1, 0);  // holds[s]: the pen in slot s (1-based), 0 empty
  for (int p = 1; p <= slots; ++p) {
    const int s = home_slot(pens, p);
    if (s >= 1 && s <= slots && holds[static_cast<size_t>(s)] == 0) holds[static_cast<size_t>(s)] = p;
  }
  auto slot_of = [&](int p) {
    for (int s = 1; s <= slots; ++s)
      if (holds[static_cast<size_t>(s)] == p) return s;
    return 0;
  };
  std::vector<PenSlot> out;
  for (size_t li = 0; li < plan.layers.size(); ++li) {
    PenSlot ps;
    ps.pen = pen_of(plan.layers[li], li);
    if (slot_of(ps.pen) == 0) {
      // The next `slots` different pens from here on stay or go in.
      std::vector<size_t> first_use;  // layer index of each pen of the window
      for (size_t k = li; k < plan.layers.size() && first_use.size() < static_cast<size_t>(slots); ++k) {
        const int p = pen_of(plan.layers[k], k);
        if (std::none_of(first_use.begin(), first_use.end(), [&](size_t j) { return pen_of(plan.layers[j], j) == p; }))
          first_use.push_back(k);
      }
      auto wanted = [&](int p) {
        return std::any_of(first_use.begin(), first_use.end(), [&](size_t j) { return pen_of(plan.layers[j], j) == p; });
      };
      for (int s = 1; s <= slots; ++s)
        if (!wanted(holds[static_cast<size_t>(s)])) holds[static_cast<size_t>(s)] = 0;
      for (size_t j : first_use) {
        const int p = pen_of(plan.layers[j], j);
        if (slot_of(p) != 0) continue;
        int s = home_slot(pens, p);
        if (s < 1 || s > slots || holds[static_cast<size_t>(s)] != 0) s = slot_of(0);
        holds[static_cast<size_t>(s)] = p;
        ps.reload.push_back({p, s, plan.layers[j].pen.name, plan.layers[j].pen.color});
      }
    }
    ps.slot = slot_of(ps.pen);
    out.push_back(std::move(ps));
  }
  return out;
}

std::string reload_message(const std::vector<PenLoad>& loads) {
  std::string m = "load";
  for (size_t i = 0; i < loads.size(); ++i) {
    const PenLoad& l = loads[i];
    m += (i ? ", pen " : " pen ") + std::to_string(l.pen) + " " + l.name + " " + l.color.hex() + " in slot " +
         std::to_string(l.slot);
  }
  return m;
}

}  // namespace stipplot
