#pragma once
// NelderMeadOptimizer: downhill simplex (Nelder–Mead) local search over the 6 pose parameters, in scaled units
// (see PoseOptimizer.h). Uses the dimension-adaptive coefficients of Gao & Han (2012), which behave better than the
// classic ones in 6-D, and restarts from the best vertex after convergence to guard against a collapsed simplex.

#include "Search/ObjectiveEvaluator.h"
#include "Search/PoseOptimizer.h"

namespace fct {

/// Settings of the downhill simplex, in scaled units (about 1 mm of bone-surface motion each).
struct NelderMeadOptions {
  double initialStep = 2.0;      ///< edge of the initial simplex along each axis, scaled units (> tolerance)
  double tolerance = 0.01;       ///< stop when every vertex is within this of the best along every axis, scaled units
  int maxEvaluations = 2000;     ///< cap on objective evaluations per call (> 0)
  int restarts = 1;              ///< fresh simplexes built around the converged best (>= 0)
};

/// Downhill simplex minimizer.
class NelderMeadOptimizer : public PoseOptimizer {
 public:
  /// A minimizer with the given options (checked when minimize() is called).
  explicit NelderMeadOptimizer(NelderMeadOptions options = {}) : m_options(options) {}

  std::string name() const override { return "nelder-mead"; }

  /// Runs one local search from `start_scaled` inside another strategy's evaluator (which counts, caps and cancels);
  /// returns the best scaled point and its value, and sets `converged` if the tolerance was reached.
  std::pair<PoseVector, double> searchScaled(ObjectiveEvaluator& evaluator, const PoseVector& start_scaled,
                                             bool* converged) const;

  /// Checks the options; the error names the bad option and its value.
  Status validateOptions() const override;

  const NelderMeadOptions& options() const { return m_options; }

 protected:
  /// One local search from `start` with restarts; reports progress every 25 evaluations and once at the end.
  OptimizationResult search(const PoseObjective& objective, const PoseVector& start, const PoseVector& scales,
                            const ProgressMonitor& monitor) const override;

 private:
  NelderMeadOptions m_options;
};

}  // namespace fct
