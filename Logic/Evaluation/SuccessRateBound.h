#pragma once
// SuccessRateBound: how low a success rate can be, given the trials that measured it (exact Clopper-Pearson bound),
// so that a study reports "20/20, >= 86 %" rather than a bare 100 %.

namespace fct {

/// Confidence bounds on a binomial success rate.
class SuccessRateBound {
 public:
  /// The one-sided Clopper-Pearson lower bound on the success probability after `successes` of `trials`, at
  /// `confidence` (e.g. 0.95): the p at which at least `successes` successes have probability 1 - confidence. 0 for
  /// no success; NaN for no trials, successes outside 0..trials, or confidence outside (0, 1).
  static double lower(int successes, int trials, double confidence = 0.95);
};

}  // namespace fct
