#pragma once
// BobyqaOptimizer: NLopt's BOBYQA (Powell 2009) as a local pose search, in scaled units (see PoseOptimizer.h). It fits
// a quadratic model of the objective through 2n+1 = 13 points and moves inside a trust region that starts at the
// initial step and shrinks to the tolerance, so on a smooth similarity it needs a fraction of the simplex's
// evaluations (docs/performance.md, "Levers measured"). No bounds; restarts start a fresh model at the best pose.
// An objective that is NaN or +infinity (a pose whose DRR leaves the image) is passed to the model as the worst
// finite value seen so far, since the quadratic model needs a number.

#include "Search/LocalPoseOptimizer.h"

namespace fct {

/// BOBYQA local search through NLopt.
class BobyqaOptimizer : public LocalPoseOptimizer {
 public:
  /// A search with the given options (checked when minimize() is called; their method is not looked at).
  explicit BobyqaOptimizer(LocalSearchOptions options = {}) : LocalPoseOptimizer(options) {}

  std::string name() const override { return "bobyqa"; }

  std::pair<PoseVector, double> searchScaled(ObjectiveEvaluator& evaluator, const PoseVector& start_scaled,
                                             bool* converged) const override;
};

}  // namespace fct
