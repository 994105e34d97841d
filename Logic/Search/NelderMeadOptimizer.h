#pragma once
// NelderMeadOptimizer: downhill simplex (Nelder–Mead) local search over the 6 pose parameters, in scaled units
// (see PoseOptimizer.h). Uses the dimension-adaptive coefficients of Gao & Han (2012), which behave better than the
// classic ones in 6-D, and restarts from the best vertex after convergence to guard against a collapsed simplex.

#include "Search/LocalPoseOptimizer.h"

namespace fct {

/// Settings of the downhill simplex: the local search options (the initial step is the simplex edge; the tolerance
/// bounds every vertex's distance from the best along every axis).
using NelderMeadOptions = LocalSearchOptions;

/// Downhill simplex minimizer.
class NelderMeadOptimizer : public LocalPoseOptimizer {
 public:
  /// A minimizer with the given options (checked when minimize() is called; their method is not looked at).
  explicit NelderMeadOptimizer(NelderMeadOptions options = {}) : LocalPoseOptimizer(options) {}

  std::string name() const override { return "nelder-mead"; }

  std::pair<PoseVector, double> searchScaled(ObjectiveEvaluator& evaluator, const PoseVector& start_scaled,
                                             bool* converged) const override;
};

}  // namespace fct
