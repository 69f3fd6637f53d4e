#pragma once
// Which slot of a pen carousel each planned pen is in, and the reloads a plan needs when
// it uses more pens (or other pens) than the machine holds. The machine starts with pens
// 1..count in their home slots (the profile's [pen] map, else pen n in slot n). When a
// layer's pen is not loaded, the operator reloads: the next `count` different pens the
// plan uses from there on are put in (those already in stay where they are), so no plan
// order needs fewer reloads. The writers turn each reload into a pause naming the pens.
#include <string>
#include <vector>

#include "drivers/device/profile.hpp"
#include "plan/plan.hpp"

namespace stipplot {

struct PenLoad {
  int pen = 0, slot = 0;
  std::string name;
  Color color;
};

struct PenSlot {
  int pen = 0;                  // the layer's pen number (Pen::number, or its position)
  int slot = 1;                 // where that pen sits when the layer is drawn (HPGL SP)
  std::vector<PenLoad> reload;  // pens to load before the layer; empty: none
};

// One entry per plan layer. O(layers x count).
std::vector<PenSlot> plan_pen_slots(const Plan& plan, const PenSetup& pens);

// "load pen 7 red #ff0000 in slot 1, pen 8 blue #0000ff in slot 2".
std::string reload_message(const std::vector<PenLoad>& loads);

}  // namespace stipplot
