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

namespace {

// Where two runs put the time as a power of the knob, t = c k^p, the knob that power law
// gives `aim`, from the run nearest it: the time of a sparse drawing is far from linear in
// k (a tree's lifts and travel: t ~ k^0.5 at 1 % of its points), which a ratio to the
// prediction corrects only slowly. 0 when the runs say nothing (one run, equal knobs or
// times, or a time falling with k).
double power_law_knob(const std::vector<std::pair<double, double>>& tried, double aim) {
  if (tried.size() < 2) return 0;
  // The two runs nearest the aim (in log time).
  std::vector<std::pair<double, double>> r = tried;
  std::sort(r.begin(), r.end(), [aim](const auto& x, const auto& y) {
    return std::abs(std::log(x.second / aim)) < std::abs(std::log(y.second / aim));
  });
  const auto [k1, t1] = r[0];
  const auto [k2, t2] = r[1];
  if (!(k1 > 0 && k2 > 0 && t1 > 0 && t2 > 0) || k1 == k2 || t1 == t2) return 0;
  const double p = std::log(t2 / t1) / std::log(k2 / k1);
  if (!(p > 0.1 && p < 10)) return 0;
  return std::clamp(k1 * std::pow(aim / t1, 1 / p), 0.0, 1.0);
}

}  // namespace

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
  // Correct with the measured ratio; a third run only when still over the budget, by the
  // power law through the two runs (the prediction's error changes with k).
  double scale = out.correction;
  for (int attempt = 0; attempt < 2 && !kept(k, t); ++attempt) {
    if (attempt == 1 && t <= budget) break;
    const double law = power_law_knob(tried, aim);
    const double next = law > 0 ? law : knob_for(aim, scale, predict);
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
  // below the lowest knob that was over, by the power law of the runs nearest the aim (or
  // the latest ratio), at most 0.9 of it and then half, so the kept drawing is within the
  // budget. At most four more runs.
  for (int extra = 0; t > budget && k > 0 && extra < 4; ++extra) {
    double over = k;
    for (const auto& [kk, tt] : tried)
      if (tt > budget) over = std::min(over, kk);
    const double law = power_law_knob(tried, aim);
    k = std::min(law > 0 ? law : knob_for(aim, scale, predict), (extra == 0 ? 0.9 : 0.5) * over);
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
