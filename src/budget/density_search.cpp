#include "budget/density_search.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "util/error.hpp"

namespace stipplot::budget {

double knob_for(double seconds, double scale, const std::function<double(double)>& predict) {
  if (scale * predict(1.0) < seconds) return 1.0;
  if (scale * predict(0.0) >= seconds) return 0.0;
  double lo = 0, hi = 1;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (scale * predict(mid) < seconds ? lo : hi) = mid;
  }
  return lo;
}

SearchOutcome choose_density(const SearchOptions& opt, const std::function<double(double)>& predict,
                             const std::function<double(double)>& run, const std::function<void(double)>& calibrate) {
  require_positive("--time", opt.budget_s);
  const double budget = opt.budget_s, aim = opt.target * budget;
  SearchOutcome out;
  double k = knob_for(aim, 1.0, predict);
  if (calibrate) {
    calibrate(k);
    k = knob_for(aim, 1.0, predict);
  }
  out.predicted = predict(k);
  double t = run(k);
  std::vector<std::pair<double, double>> tried{{k, t}};
  out.runs = 1;
  out.correction = out.predicted > 0 ? t / out.predicted : 1;
  auto kept = [&](double kk, double tt) {
    const bool in_band = tt <= budget && tt >= opt.accept * budget;
    const bool finest_fits = kk >= 1.0 && tt <= budget;
    const bool coarsest_over = kk <= 0.0 && tt > budget;
    return in_band || finest_fits || coarsest_over;
  };
  // Correct with the measured ratio; a third run only when still over the budget, with
  // the ratio of the second run (the prediction's error changes slowly with k).
  double scale = out.correction;
  for (int attempt = 0; attempt < 2 && !kept(k, t); ++attempt) {
    if (attempt == 1 && t <= budget) break;
    const double next = knob_for(aim, scale, predict);
    if (next == k) break;
    k = next;
    const double p = predict(k);
    t = run(k);
    tried.emplace_back(k, t);
    ++out.runs;
    if (p > 0) scale = t / p;
  }
  // Over the budget after the corrections: keep the fullest earlier run that fitted.
  if (t > budget) {
    double best_t = -1, best_k = k;
    for (const auto& [kk, tt] : tried)
      if (tt <= budget && tt > best_t) best_t = tt, best_k = kk;
    if (best_t >= 0) k = best_k, t = best_t;
  }
  // None fitted (the time is far from linear in k there: a sparse tree's travel): go on
  // below the lowest knob that was over, by the latest ratio, and then by halves, so the
  // kept drawing is within the budget. At most four more runs.
  for (int extra = 0; t > budget && k > 0 && extra < 4; ++extra) {
    double over = k;
    for (const auto& [kk, tt] : tried)
      if (tt > budget) over = std::min(over, kk);
    k = std::min(knob_for(aim, scale, predict), (extra == 0 ? 0.9 : 0.5) * over);
    const double p = predict(k);
    t = run(k);
    tried.emplace_back(k, t);
    ++out.runs;
    if (p > 0) scale = t / p;
  }
  out.knob = k;
  out.seconds = t;
  out.finest = k >= 1.0 && t <= budget;
  out.coarsest = k <= 0.0 && t > budget;
  return out;
}

}  // namespace stipplot::budget
