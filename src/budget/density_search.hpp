#pragma once
// Choosing a method's density for a plot-time budget. A method exposes one knob k in
// [0, 1] whose plot time grows with k (1 = the finest drawing it makes), a cheap
// prediction of that time from image statistics and the machine's mark costs, and the
// run itself. The search predicts k for the target, runs once, and corrects once from
// the measured error when the run missed the accepted band; a third run happens only if
// the corrected run is still over the budget. So it costs one run of the method and its
// quick estimate, two when the prediction was off, and the plan stays within budget.
#include <functional>

namespace stipplot::budget {

struct SearchOptions {
  double budget_s = 3600;
  double target = 0.93;  // aim at this share of the budget (room for the prediction's error)
  double accept = 0.85;  // a run at or above this share (and within the budget) is kept
};

struct SearchOutcome {
  double knob = 1;
  double seconds = 0;         // the quick estimate of the kept run
  double predicted = 0;       // the prediction at the first knob
  double correction = 1;      // measured / predicted of the first run
  int runs = 0;
  bool finest = false;        // the finest drawing fits: the budget is more than it needs
  bool coarsest = false;      // even the coarsest drawing is over budget
};

// `predict(k)` must be cheap; `run(k)` runs the method at k and returns its quick plot
// estimate (the caller keeps every run's result). Both must be non-decreasing in k.
// `calibrate(k)`, if given, is called once at the first predicted knob before any run:
// a method may run a cheap pilot there to correct its prediction (the knob is then
// predicted again). Time: ~100 predictions, the pilot, 1-3 runs (up to 7 when none of
// the first three fits the budget).
SearchOutcome choose_density(const SearchOptions& opt, const std::function<double(double)>& predict,
                             const std::function<double(double)>& run,
                             const std::function<void(double)>& calibrate = {});

// The smallest k in [0, 1] with scale * predict(k) >= seconds (1 if none). Bisection,
// 40 predictions.
double knob_for(double seconds, double scale, const std::function<double(double)>& predict);

}  // namespace stipplot::budget
