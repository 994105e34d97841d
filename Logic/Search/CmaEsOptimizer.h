#pragma once
// CmaEsOptimizer: covariance matrix adaptation evolution strategy (Hansen's (mu/mu_w, lambda)-CMA-ES with rank-one and
// rank-mu updates, as in "The CMA Evolution Strategy: A Tutorial", 2016), over the 6 pose parameters in scaled units.
// A compact own implementation with Eigen; the alternative global strategy to GeneticSearchOptimizer.

#include <cstdint>

#include "Search/PoseOptimizer.h"

namespace fct {

/// Settings of CMA-ES, in scaled units (about 1 mm of bone-surface motion each).
struct CmaEsOptions {
  double initialSigma = 5.0;   ///< initial step size (standard deviation), scaled units (> tolerance)
  int populationSize = 0;      ///< offspring per generation (lambda); 0 = the default 4 + floor(3 ln 6) = 9; else >= 4
  double tolerance = 0.01;     ///< stop when sigma * sqrt(largest variance) is below this, scaled units
  int maxEvaluations = 5000;   ///< cap on objective evaluations (> 0)
  std::uint32_t seed = 1;      ///< random seed; the same seed gives the same result
};

/// CMA-ES minimizer.
class CmaEsOptimizer : public PoseOptimizer {
 public:
  /// A minimizer with the given options (checked when minimize() is called).
  explicit CmaEsOptimizer(CmaEsOptions options = {}) : m_options(options) {}

  std::string name() const override { return "cma-es"; }

  /// Checks the options; the error names the bad option and its value.
  Status validateOptions() const override;

  const CmaEsOptions& options() const { return m_options; }

 protected:
  /// CMA-ES from `start` (the initial mean). Reports progress per generation with the evaluation count and best
  /// value; fills OptimizationResult::generations.
  OptimizationResult search(const PoseObjective& objective, const PoseVector& start, const PoseVector& scales,
                            const ProgressMonitor& monitor) const override;

 private:
  CmaEsOptions m_options;
};

}  // namespace fct
