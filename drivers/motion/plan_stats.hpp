#pragma once
// What a plan costs: per layer and in total, pen-down and pen-up lengths, pen lifts
// and estimated plot time (the motion model's), for reports and --json.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "drivers/motion/time_model.hpp"
#include "plan/plan.hpp"

namespace stipplot {

struct LayerStats {
  std::string pen;
  size_t strokes = 0;       // pen-down runs, touches included
  size_t touches = 0;       // one-point strokes (dots)
  size_t pen_lifts = 0;     // one per stroke
  double pen_down_mm = 0;
  double pen_up_mm = 0;     // travel to each stroke, from where the pen was
  double seconds = 0;       // estimated, motion model
};

struct PlanStats {
  std::vector<LayerStats> layers;
  LayerStats total;         // sums; total.pen_up_mm includes the return home if asked
  double home_mm = 0;       // the return to the origin, 0 unless asked for
};

// O(points + motion model). The pen starts at `origin`; each layer starts where the
// previous one ended.
PlanStats plan_stats(const Plan& plan, const MotionParams& m, Vec2 origin = {0, 0}, bool return_home = false);

// The same lengths and counts with every `seconds` 0, for a job whose written lines are
// timed instead (cli/job_estimate.hpp): the motion model's run would be thrown away (a
// third of a second for 1M dots). O(points).
PlanStats plan_lengths(const Plan& plan, Vec2 origin = {0, 0}, bool return_home = false);

nlohmann::json to_json(const LayerStats& s);
nlohmann::json to_json(const PlanStats& s);  // {"layers": [...], "total": {...}, "home_mm": x}

}  // namespace stipplot
